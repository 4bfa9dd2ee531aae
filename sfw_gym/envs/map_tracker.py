"""Map-quality metrics kept up to date cell by cell, so that every step's info is cheap.

The figures equal `sfw_gym.mapping.metrics` on the full maps (a test holds them to it); here they
cost O(cells changed this step) instead of O(grid).
"""

from __future__ import annotations

import numpy as np
from numba import njit
from scipy import ndimage

from sfw_gym.mapping import metrics
from sfw_gym.mapping.grid import CLASS_FREE as FREE
from sfw_gym.mapping.grid import CLASS_UNKNOWN as UNKNOWN
from sfw_gym.mapping.grid import CLASS_WALL as WALL
from sfw_gym.mapping.grid import belief_classes, u8_class

# Counter slots.
_N_KNOWN, _N_EST_FREE, _N_EST_WALL, _COVERED, _AGREE, _KNOWN_BOTH = range(6)
_FREE_INTER, _WALL_NEAR, _INTERIOR_FOUND = 6, 7, 8


@njit(cache=True)
def _account(
    cell, cls, sign, truth_cls, near_wall, interior, found_by, offsets, n_rows, n_cols, counts
):
    """Add (sign=+1) or remove (-1) one cell's estimated class from the counters."""
    if cls == UNKNOWN:
        return
    t = truth_cls[cell]
    counts[_N_KNOWN] += sign
    if t == FREE:
        counts[_COVERED] += sign
    if t != UNKNOWN:
        counts[_KNOWN_BOTH] += sign
        if t == cls:
            counts[_AGREE] += sign
    if cls == FREE:
        counts[_N_EST_FREE] += sign
        if t == FREE:
            counts[_FREE_INTER] += sign
        return
    counts[_N_EST_WALL] += sign
    if near_wall[cell]:
        counts[_WALL_NEAR] += sign
    r0 = cell // n_cols
    c0 = cell % n_cols
    for j in range(offsets.shape[0]):  # an estimated wall vouches for interior walls nearby
        r = r0 + offsets[j, 0]
        c = c0 + offsets[j, 1]
        if 0 <= r < n_rows and 0 <= c < n_cols and interior[r * n_cols + c]:
            other = r * n_cols + c
            before = found_by[other]
            found_by[other] += sign
            if before == 0 and sign > 0:
                counts[_INTERIOR_FOUND] += 1
            elif before == 1 and sign < 0:
                counts[_INTERIOR_FOUND] -= 1


@njit(cache=True)
def _apply(
    changed, est_u8, est_cls, truth_cls, near_wall, interior, found_by, offsets, n_cols, counts
):
    n_rows = est_cls.shape[0] // n_cols
    for i in range(changed.shape[0]):
        cell = changed[i]
        new = u8_class(est_u8[cell])
        old = est_cls[cell]
        if new == old:
            continue
        _account(
            cell, old, -1, truth_cls, near_wall, interior, found_by, offsets, n_rows, n_cols, counts
        )
        _account(
            cell, new, 1, truth_cls, near_wall, interior, found_by, offsets, n_rows, n_cols, counts
        )
        est_cls[cell] = new


class MapTracker:
    """Coverage, paper IoU, free IoU, wall precision and interior-wall recall of a belief map.

    Each equals its `sfw_gym.mapping.metrics` function on the full maps, except that an undefined
    ratio (empty denominator) reads 0.0 here rather than nan.

    Args:
        truth_u8: the ground-truth grid (0 wall, 255 free, 127 outside).
        tolerance_cells: wall tolerance of precision and recall (as in `sfw_gym.mapping.metrics`).
    """

    def __init__(self, truth_u8: np.ndarray, tolerance_cells: float = 2) -> None:
        self.truth_u8 = truth_u8
        free, wall, _ = belief_classes(truth_u8)
        self._truth_cls = (
            np.where(wall, WALL, np.where(free, FREE, UNKNOWN)).astype(np.int8).ravel()
        )
        dist = ndimage.distance_transform_edt(~wall) if wall.any() else np.full(wall.shape, np.inf)
        self._near_wall = (dist <= tolerance_cells).ravel()
        self._interior = metrics.interior_wall_cells(truth_u8).ravel()
        t = int(np.floor(tolerance_cells))
        dr, dc = np.mgrid[-t : t + 1, -t : t + 1]
        keep = dr**2 + dc**2 <= tolerance_cells**2
        self._offsets = np.stack([dr[keep], dc[keep]], axis=1).astype(np.int64)
        self._found_by = np.zeros(truth_u8.size, np.int32)
        self._est_cls = np.zeros(truth_u8.size, np.int8)
        self._counts = np.zeros(9, np.int64)
        self._n_cells = truth_u8.size
        self._n_truth_free = int(free.sum())
        self._n_interior = int(self._interior.sum())

    def apply(self, changed_cells: np.ndarray, est_u8: np.ndarray) -> None:
        """Account for the cells whose class changed in the last map update."""
        if len(changed_cells):
            _apply(
                np.asarray(changed_cells, np.int64),
                est_u8.ravel(),
                self._est_cls,
                self._truth_cls,
                self._near_wall,
                self._interior,
                self._found_by,
                self._offsets,
                self.truth_u8.shape[1],
                self._counts,
            )

    def metrics(self) -> dict[str, float]:
        """``coverage``, ``map_iou``, ``free_iou``, ``wall_precision`` and
        ``interior_wall_recall``: :mod:`sfw_gym.mapping.metrics`' figures of the current belief
        (the paper's IoU for ``map_iou``), from the counts kept up to date."""
        c, ratio = self._counts.tolist(), self._ratio
        inter = c[_FREE_INTER]
        return {
            "coverage": ratio(c[_COVERED], self._n_truth_free),
            "map_iou": ratio(c[_AGREE], c[_KNOWN_BOTH]),
            "free_iou": ratio(inter, c[_N_EST_FREE] + self._n_truth_free - inter),
            "wall_precision": ratio(c[_WALL_NEAR], c[_N_EST_WALL]),
            "interior_wall_recall": ratio(c[_INTERIOR_FOUND], self._n_interior),
        }

    @staticmethod
    def _ratio(num: int, den: int) -> float:
        # 0.0 while undefined (no wall estimated yet, …): info stays comparable and averageable;
        # `sfw_gym.mapping.metrics` returns nan there instead.
        return float(num / den) if den else 0.0

    @property
    def known_fraction(self) -> float:
        """Fraction of the grid the belief classifies (free or wall): the robot's own view."""
        return self._counts[_N_KNOWN] / self._n_cells

    def map_mse(self, est_u8: np.ndarray) -> float:
        """`sfw_gym.mapping.metrics.map_mse` (graded values: on the full map, at episode end)."""
        return metrics.map_mse(est_u8, self.truth_u8)
