"""Grid geometry and the uint8 occupancy convention shared by maps and metrics.

Arrays are indexed ``[row, col]`` = ``[y, x]``. Row 0 lies at ``origin_xy[1]`` and column 0 at
``origin_xy[0]``; y grows with the row index. The centre of cell ``(row, col)`` is
``origin + (index + 0.5) * resolution_m``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numba import njit

from sfw_gym.core.constants import U8_FREE_MIN, U8_WALL_MAX
from sfw_gym.core.errors import ConfigError


def belief_classes(belief_u8: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Read a uint8 map (0 wall, 255 free, 127 unknown; graded values allowed) by thirds.

    Returns:
        ``(free, wall, unknown)`` boolean masks of the map's shape
        (:data:`~sfw_gym.core.constants.U8_WALL_MAX`, :data:`~sfw_gym.core.constants.U8_FREE_MIN`).
    """
    b = np.asarray(belief_u8)
    wall = b <= U8_WALL_MAX
    free = b >= U8_FREE_MIN
    return free, wall, ~(free | wall)


#: Class codes of :func:`u8_class` (numba kernels keep one small int class per cell).
CLASS_UNKNOWN, CLASS_FREE, CLASS_WALL = 0, 1, 2


@njit(cache=True)
def u8_class(v):
    """The class code of one belief value: :func:`belief_classes` for a scalar, inside kernels."""
    if v <= U8_WALL_MAX:
        return CLASS_WALL
    if v >= U8_FREE_MIN:
        return CLASS_FREE
    return CLASS_UNKNOWN


@dataclass(frozen=True)
class GridSpec:
    """Geometry of a regular 2-D grid in world metres.

    Attributes:
        origin_xy: World (x, y) of the outer corner of cell (0, 0).
        resolution_m: Cell edge length in metres.
        shape: ``(n_rows, n_cols)``.
    """

    origin_xy: tuple[float, float]
    resolution_m: float
    shape: tuple[int, int]

    def __post_init__(self) -> None:
        try:
            ox, oy = (float(v) for v in self.origin_xy)
        except (TypeError, ValueError) as exc:
            raise ConfigError(f"origin_xy must be two numbers, got {self.origin_xy!r}") from exc
        if not (math.isfinite(ox) and math.isfinite(oy)):
            raise ConfigError(f"origin_xy must be finite, got {self.origin_xy!r}")
        res = self.resolution_m
        if isinstance(res, bool) or not isinstance(res, (int, float, np.floating, np.integer)):
            raise ConfigError(f"resolution_m must be a number, got {res!r}")
        if not (math.isfinite(res) and res > 0):
            raise ConfigError(f"resolution_m must be finite and > 0, got {res!r}")
        try:
            rows, cols = self.shape
        except (TypeError, ValueError) as exc:
            raise ConfigError(f"shape must be (n_rows, n_cols), got {self.shape!r}") from exc
        for name, n in (("n_rows", rows), ("n_cols", cols)):
            if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
                raise ConfigError(f"shape {name} must be an int >= 1, got {n!r}")
        object.__setattr__(self, "origin_xy", (ox, oy))
        object.__setattr__(self, "resolution_m", float(res))
        object.__setattr__(self, "shape", (int(rows), int(cols)))

    @classmethod
    def covering(
        cls,
        bounds: tuple[float, float, float, float],
        resolution_m: float,
        margin_m: float = 0.0,
    ) -> GridSpec:
        """The smallest grid of ``resolution_m`` cells that covers ``bounds`` plus a margin.

        Args:
            bounds: ``(xmin, ymin, xmax, ymax)`` in metres.
            resolution_m: Cell edge length in metres.
            margin_m: Extra border added on every side, metres (>= 0).

        Returns:
            A grid whose origin is ``(xmin - margin_m, ymin - margin_m)``.
        """
        try:
            xmin, ymin, xmax, ymax = (float(v) for v in bounds)
        except (TypeError, ValueError) as exc:
            raise ConfigError(f"bounds must be (xmin, ymin, xmax, ymax), got {bounds!r}") from exc
        if not all(math.isfinite(v) for v in (xmin, ymin, xmax, ymax)):
            raise ConfigError(f"bounds must be finite, got {bounds!r}")
        if not (xmax > xmin and ymax > ymin):
            raise ConfigError(f"bounds need xmax > xmin and ymax > ymin, got {bounds!r}")
        if not (math.isfinite(margin_m) and margin_m >= 0):
            raise ConfigError(f"margin_m must be finite and >= 0, got {margin_m!r}")
        if not (isinstance(resolution_m, (int, float)) and resolution_m > 0):
            raise ConfigError(f"resolution_m must be > 0, got {resolution_m!r}")
        x0, y0 = xmin - margin_m, ymin - margin_m
        # Tolerate round-off: 15 m / 0.05 m must give 300 cells, not 301.
        cols = max(1, math.ceil((xmax + margin_m - x0) / resolution_m - 1e-9))
        rows = max(1, math.ceil((ymax + margin_m - y0) / resolution_m - 1e-9))
        return cls((x0, y0), float(resolution_m), (rows, cols))

    @property
    def n_rows(self) -> int:
        """Number of rows (y direction)."""
        return self.shape[0]

    @property
    def n_cols(self) -> int:
        """Number of columns (x direction)."""
        return self.shape[1]

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """``(xmin, ymin, xmax, ymax)`` of the grid's outer edges, metres."""
        ox, oy = self.origin_xy
        return (ox, oy, ox + self.n_cols * self.resolution_m, oy + self.n_rows * self.resolution_m)

    def world_to_grid(self, xy: np.ndarray) -> np.ndarray:
        """Continuous grid coordinates ``(col, row)`` in cell units (cell centres at +0.5)."""
        xy = np.asarray(xy, dtype=np.float64)
        return (xy - np.asarray(self.origin_xy)) / self.resolution_m

    def world_to_cell(self, xy: np.ndarray) -> np.ndarray:
        """Cell index of world points.

        Args:
            xy: ``(..., 2)`` world coordinates ``(x, y)`` in metres.

        Returns:
            ``(..., 2)`` int64 array of ``(row, col)``. Points outside the grid give indices
            outside ``[0, shape)``; check with :meth:`contains`.
        """
        g = np.floor(self.world_to_grid(xy)).astype(np.int64)
        return g[..., ::-1].copy()

    def clipped_cell(self, xy: Any) -> tuple[int, int]:
        """The cell ``(row, col)`` of one world point ``(x, y)``, clipped into the grid."""
        r, c = self.world_to_cell(np.asarray(xy, np.float64)[:2])
        return min(max(int(r), 0), self.n_rows - 1), min(max(int(c), 0), self.n_cols - 1)

    def cell_to_world(self, rc: np.ndarray) -> np.ndarray:
        """World ``(x, y)`` of cell centres.

        Args:
            rc: ``(..., 2)`` integer ``(row, col)`` indices.

        Returns:
            ``(..., 2)`` float64 array of ``(x, y)`` in metres.
        """
        rc = np.asarray(rc, dtype=np.float64)
        return np.asarray(self.origin_xy) + (rc[..., ::-1] + 0.5) * self.resolution_m

    def contains(self, xy: np.ndarray) -> np.ndarray:
        """Whether world points lie inside the grid (lower edges inclusive, upper exclusive)."""
        g = self.world_to_grid(xy)
        with np.errstate(invalid="ignore"):
            return (
                (g[..., 0] >= 0)
                & (g[..., 0] < self.n_cols)
                & (g[..., 1] >= 0)
                & (g[..., 1] < self.n_rows)
            )

    def cell_centres(self) -> tuple[np.ndarray, np.ndarray]:
        """World coordinates of all cell centres as ``(X, Y)`` arrays of ``shape``."""
        ox, oy = self.origin_xy
        xs = ox + (np.arange(self.n_cols) + 0.5) * self.resolution_m
        ys = oy + (np.arange(self.n_rows) + 0.5) * self.resolution_m
        return np.meshgrid(xs, ys)
