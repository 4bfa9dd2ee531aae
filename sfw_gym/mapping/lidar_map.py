"""A log-odds occupancy grid from 2-D LiDAR scans at given poses (the inverse sensor model).

Each scan updates a cell at most once, as the classic model evaluates each cell once per scan:
``l_occ`` where a beam ends (the cell just beyond the hit point, so a hit on a wall face marks
the wall's side), else ``l_free`` where a beam passed through; a beam that returned nothing
(``inf``) marks free up to the maximum range. Log-odds add up, clamped to ``[-clamp, clamp]``.
The grid is a :class:`~sfw_gym.mapping.grid.GridSpec` (``[row, col]`` = ``[y, x]``), so the belief
maps' metrics (:mod:`sfw_gym.mapping.metrics`) score :meth:`LidarOccupancyMap.occupancy_u8`
against the env's ground truth directly.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import njit

from sfw_gym.core.constants import U8_FREE, U8_UNKNOWN, U8_WALL
from sfw_gym.core.errors import ConfigError
from sfw_gym.mapping.grid import GridSpec
from sfw_gym.mapping.raycast import ray_buffer_size, traverse_grid

_HIT_STEP = 1e-6  # cells: how far past the hit point its cell is looked up


@njit(cache=True)
def _integrate(lo, stamp, scan_id, gx, gy, dirs, ranges, max_cells, l_free, l_occ, clamp, bufs):
    """One scan's update of ``lo`` (grid coordinates: cells, ``x`` along columns).

    ``stamp`` holds, per cell, ``2 * scan_id + 1`` once a hit has set it this scan and
    ``2 * scan_id`` once a beam freed it: later beams of the scan leave such a cell alone.
    """
    rows, cols, t0, t1 = bufs
    n_rows, n_cols = lo.shape
    occ_mark = 2 * scan_id + 1
    free_mark = 2 * scan_id
    for k in range(ranges.shape[0]):  # hits first: a wall cell crossed by another beam stays hit
        r = ranges[k]
        if not math.isfinite(r):
            continue
        c = int(np.floor(gx + (r + _HIT_STEP) * dirs[k, 0]))
        w = int(np.floor(gy + (r + _HIT_STEP) * dirs[k, 1]))
        if 0 <= w < n_rows and 0 <= c < n_cols and stamp[w, c] != occ_mark:
            stamp[w, c] = occ_mark
            lo[w, c] = min(clamp, max(-clamp, lo[w, c] + l_occ))
    for k in range(ranges.shape[0]):
        r = ranges[k] if math.isfinite(ranges[k]) else max_cells
        n = traverse_grid(
            gx, gy, gx + r * dirs[k, 0], gy + r * dirs[k, 1], n_rows, n_cols, rows, cols, t0, t1
        )
        for i in range(n):
            w = rows[i]
            c = cols[i]
            if stamp[w, c] < free_mark:
                stamp[w, c] = free_mark
                lo[w, c] = min(clamp, max(-clamp, lo[w, c] + l_free))


class LidarOccupancyMap:
    """Log-odds of "occupied" per cell of ``grid``, built scan by scan.

    Args:
        grid: The map's cells (origin of the lower-left corner, resolution, ``(rows, cols)``).
        l_free: Log-odds added to a cell a beam passed through.
        l_occ: Log-odds added to the cell a beam ended in.
        clamp: Log-odds stay within ``[-clamp, clamp]``.

    Attributes:
        grid: The map's cells.
        log_odds: ``(rows, cols)`` float64 log-odds of "occupied", 0 = unknown.
    """

    def __init__(
        self, grid: GridSpec, l_free: float = -0.4, l_occ: float = 0.85, clamp: float = 5.0
    ) -> None:
        for name, value, sign in (("l_free", l_free, -1), ("l_occ", l_occ, 1), ("clamp", clamp, 1)):
            if not (math.isfinite(value) and sign * value > 0):
                raise ConfigError(
                    f"{name} must be a finite number {'<>'[sign > 0]} 0, got {value!r}"
                )
        self.grid = grid
        self.l_free, self.l_occ, self.clamp = float(l_free), float(l_occ), float(clamp)
        self.log_odds = np.zeros(grid.shape, np.float64)
        self._stamp = np.zeros(grid.shape, np.int64)
        self._scans = 0
        size = ray_buffer_size(grid.shape)
        self._bufs = (
            np.empty(size, np.int64),
            np.empty(size, np.int64),
            np.empty(size, np.float64),
            np.empty(size, np.float64),
        )

    def integrate(
        self, pose: Any, angles: np.ndarray, ranges: np.ndarray, max_range_m: float
    ) -> None:
        """Add one scan taken at ``pose`` ``(x, y, theta)``: beam ``k`` at ``theta + angles[k]``
        measured ``ranges[k]`` metres (``inf``: nothing within ``max_range_m``)."""
        p = np.asarray(pose, np.float64)
        if p.shape != (3,) or not np.isfinite(p).all():
            raise ConfigError(f"pose must be a finite (x, y, theta), got {pose!r:.80}")
        theta = float(p[2])
        a = np.asarray(angles, np.float64)
        r = np.asarray(ranges, np.float64)
        if a.ndim != 1 or a.shape != r.shape:
            raise ConfigError(f"angles and ranges must be of one (N,) shape: {a.shape}, {r.shape}")
        if not (math.isfinite(max_range_m) and max_range_m > 0):
            raise ConfigError(f"max_range_m must be a finite number > 0, got {max_range_m!r}")
        if np.isnan(r).any() or (r < 0).any():
            raise ConfigError("ranges must be >= 0 or inf, got NaN or a negative range")
        res = self.grid.resolution_m
        gx, gy = self.grid.world_to_grid(p[:2])
        dirs = np.column_stack([np.cos(theta + a), np.sin(theta + a)])
        self._scans += 1
        _integrate(
            self.log_odds,
            self._stamp,
            self._scans,
            gx,
            gy,
            dirs,
            r / res,
            max_range_m / res,
            self.l_free,
            self.l_occ,
            self.clamp,
            self._bufs,
        )

    def probability(self) -> np.ndarray:
        """P(occupied) per cell: the logistic sigmoid of the log-odds (0.5 = unknown)."""
        return 1.0 / (1.0 + np.exp(-self.log_odds))

    def occupancy_u8(self, threshold_free: float = 0.3, threshold_occ: float = 0.7) -> np.ndarray:
        """The map in the belief maps' uint8 encoding (what the metrics score): ``U8_WALL`` (0)
        where P(occupied) > ``threshold_occ``, ``U8_FREE`` (255) where it is below
        ``threshold_free``, ``U8_UNKNOWN`` (127) between."""
        if not 0.0 < threshold_free <= 0.5 <= threshold_occ < 1.0:
            raise ConfigError(
                "thresholds need 0 < threshold_free <= 0.5 <= threshold_occ < 1, got "
                f"{threshold_free!r}, {threshold_occ!r}"
            )
        p = self.probability()
        out = np.full(p.shape, U8_UNKNOWN, np.uint8)
        out[p < threshold_free] = U8_FREE
        out[p > threshold_occ] = U8_WALL
        return out
