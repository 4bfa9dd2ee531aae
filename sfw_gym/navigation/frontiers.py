"""Frontiers and hidden rooms of a belief map (map analysis for exploration).

A frontier is an unknown cell 8-adjacent to a believed-free cell of the thresholded belief;
frontier cells are grouped into 8-connected clusters (:func:`scipy.ndimage.label`). A hidden
room is a room-deep unknown pocket inside the explored extent: a room whose doorway the map
closed has no frontier at all.

The compiled kernels below serve :class:`~sfw_gym.navigation.candidates.GoalFinder`: the frontier
kept up to date where the belief changed (:func:`update_frontier`), the cells that are no goals
(:func:`excluded_cells`: near a bump, failed, walled off, or in a small unknown pocket) and the
frontier part of a candidate menu in one pass (:func:`frontier_menu`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit
from scipy import ndimage

from sfw_gym.core.angles import wrap_angle_compiled
from sfw_gym.core.constants import U8_FREE_MIN, U8_WALL_MAX
from sfw_gym.navigation.planning import belief_classes, min_over_offsets

#: 8-connectivity for scipy.ndimage.label and binary_dilation.
EIGHT_CONNECTED = np.ones((3, 3), bool)


@dataclass(frozen=True)
class Frontier:
    """One frontier cluster.

    Attributes:
        cells: ``(N, 2)`` cells ``(row, col)``.
        centroid_rc: Mean cell, ``(row, col)`` floats.
    """

    cells: np.ndarray
    centroid_rc: tuple[float, float]

    @property
    def size(self) -> int:
        """Number of cells."""
        return len(self.cells)


def frontier_mask(belief_u8: np.ndarray, exclude: np.ndarray | None = None) -> np.ndarray:
    """Unknown cells 8-adjacent to a believed-free cell (optionally minus ``exclude``)."""
    free, _, unknown = belief_classes(belief_u8)
    mask = unknown & ndimage.binary_dilation(free, structure=EIGHT_CONNECTED)
    if exclude is not None:
        mask &= ~exclude
    return mask


def hidden_rooms(belief_u8: np.ndarray, min_depth_cells: float) -> np.ndarray:
    """Per cell, its depth (cells to the nearest known cell) in the unknown space inside the
    bounding box of the believed-free cells, where that depth is at least ``min_depth_cells``
    (room-sized pockets, not the band of unknown cells along a wall); else 0."""
    free, _, unknown = belief_classes(belief_u8)
    rows, cols = np.flatnonzero(free.any(1)), np.flatnonzero(free.any(0))
    if not len(rows):
        return np.zeros(belief_u8.shape)
    inside = np.zeros(belief_u8.shape, bool)
    inside[rows[0] : rows[-1] + 1, cols[0] : cols[-1] + 1] = True
    depth = _distance_to_zeros(unknown & inside)
    return np.where(depth >= min_depth_cells, depth, 0.0)


def _distance_to_zeros(ones: np.ndarray) -> np.ndarray:
    """``scipy.ndimage.distance_transform_edt(ones)``, computed on the bounding box of the ones
    grown by a cell: a ring of zeros holds, for every one, a zero at least as near as any
    beyond it (clamp that zero onto the ring)."""
    rows, cols = np.flatnonzero(ones.any(1)), np.flatnonzero(ones.any(0))
    out = np.zeros(ones.shape)
    if len(rows):
        box = (
            slice(max(rows[0] - 1, 0), rows[-1] + 2),
            slice(max(cols[0] - 1, 0), cols[-1] + 2),
        )
        out[box] = ndimage.distance_transform_edt(ones[box])
    return out


def find_frontiers(
    belief_u8: np.ndarray,
    min_size_cells: int = 1,
    exclude: np.ndarray | None = None,
    *,
    mask: np.ndarray | None = None,
) -> list[Frontier]:
    """Frontier clusters of a belief map (0 wall, 255 free, 127 unknown), largest first.

    Args:
        belief_u8: The belief, ``[row, col]``.
        min_size_cells: Clusters smaller than this are dropped.
        exclude: Optional mask of cells that are never frontier cells.
        mask: :func:`frontier_mask` of ``belief_u8``, if known (not modified).

    Returns:
        The clusters (8-connected), sorted by decreasing size.
    """
    if mask is None:
        mask = frontier_mask(belief_u8, exclude)
    elif exclude is not None:
        mask = mask & ~exclude
    out = []
    for cells in cluster_cells(mask, min_size_cells):
        out.append(Frontier(cells, (float(cells[:, 0].mean()), float(cells[:, 1].mean()))))
    return out


def cluster_cells(mask: np.ndarray, min_size_cells: int = 1) -> list[np.ndarray]:
    """The 8-connected clusters of ``mask`` with at least ``min_size_cells`` cells, largest first
    (ties in the order of their first cell in raster order, as :func:`scipy.ndimage.label`
    numbers them), each as ``(N, 2)`` cells ``(row, col)`` in raster order."""
    flat = np.flatnonzero(mask)
    if not len(flat):
        return []
    members, bounds = _clusters(np.ascontiguousarray(mask), flat, int(min_size_cells))
    cells = np.stack(np.divmod(members, mask.shape[1]), axis=1)
    return [cells[bounds[k] : bounds[k + 1]] for k in range(len(bounds) - 1)]


@njit(cache=True)
def window_3x3(i, h, w):  # pragma: no cover (compiled)
    """The rows ``[r0, r1)`` and columns ``[c0, c1)`` of the 3 × 3 window around the flat cell
    ``i`` of an ``h × w`` grid, clipped to the grid: the cell and its 8 neighbours."""
    r = i // w
    c = i - r * w
    return max(r - 1, 0), min(r + 2, h), max(c - 1, 0), min(c + 2, w)


@njit(cache=True)
def _clusters(mask, flat, min_size):  # pragma: no cover (compiled)
    """Flood-fill the 8-connected clusters of ``mask`` from its cells ``flat`` (raster order),
    numbering them by their first cell; return the cells of the clusters of ``min_size`` or more
    cells grouped by cluster (largest first, ties by number; raster order inside) and the groups'
    bounds."""
    h, w = mask.shape
    todo = mask.ravel().copy()  # cells not labelled yet
    members = np.empty(len(flat), np.int64)  # cells grouped by cluster, in fill order
    starts = np.empty(len(flat) + 1, np.int64)
    n_labels, tail = 0, 0
    for k in range(len(flat)):
        if not todo[flat[k]]:
            continue
        todo[flat[k]] = False
        starts[n_labels] = head = tail
        members[tail] = flat[k]
        tail += 1
        while head < tail:
            r0, r1, c0, c1 = window_3x3(members[head], h, w)
            head += 1
            for rr in range(r0, r1):
                for cc in range(c0, c1):
                    if todo[rr * w + cc]:
                        todo[rr * w + cc] = False
                        members[tail] = rr * w + cc
                        tail += 1
        n_labels += 1
    starts[n_labels] = tail
    size = starts[1 : n_labels + 1] - starts[:n_labels]
    by_size = np.argsort(-size, kind="mergesort")  # stable: ties keep their numbering
    n_kept = 0
    while n_kept < n_labels and size[by_size[n_kept]] >= min_size:
        n_kept += 1
    bounds = np.zeros(n_kept + 1, np.int64)
    out = np.empty(tail, np.int64)
    for q in range(n_kept):
        m = by_size[q]
        bounds[q + 1] = bounds[q] + size[m]
        out[bounds[q] : bounds[q + 1]] = np.sort(members[starts[m] : starts[m + 1]])
    return out[: bounds[n_kept]], bounds


@njit(cache=True)
def update_frontier(belief, seen, changed, frontier):  # pragma: no cover (compiled)
    """Copy the changed cells of ``belief`` into ``seen`` and recompute ``frontier`` (unknown
    cells 8-adjacent to a believed-free cell) around them."""
    h, w = belief.shape
    for i in changed:
        seen.flat[i] = belief.flat[i]
    for i in changed:
        r0, r1, c0, c1 = window_3x3(i, h, w)
        for r in range(r0, r1):
            for c in range(c0, c1):
                v = belief[r, c]
                is_frontier = False
                if U8_WALL_MAX < v < U8_FREE_MIN:
                    for rr in range(max(r - 1, 0), min(r + 2, h)):
                        for cc in range(max(c - 1, 0), min(c + 2, w)):
                            if belief[rr, cc] >= U8_FREE_MIN:
                                is_frontier = True
                frontier[r, c] = is_frontier


@njit(cache=True)
def _small_pockets(belief, seeds, n_big):  # pragma: no cover (compiled)
    """Per seed cell (flat indices): whether it is an unknown cell of ``belief`` whose
    8-connected unknown component has fewer than ``n_big`` cells. Each flood fill stops at
    ``n_big`` cells or at a cell known to lie in a big component, so every cell is visited at
    most once."""
    h, w = belief.shape
    b = belief.ravel()
    state = np.zeros(h * w, np.int8)  # 0 unseen, 1 being filled, 2 small, 3 big
    queue = np.empty(max(n_big, 1), np.int64)
    for i0 in seeds:
        if state[i0] != 0 or not U8_WALL_MAX < b[i0] < U8_FREE_MIN:
            continue
        state[i0] = 1
        queue[0] = i0
        n, head, big = 1, 0, n_big <= 1
        while head < n and not big:
            r0, r1, c0, c1 = window_3x3(queue[head], h, w)
            head += 1
            for rr in range(r0, r1):
                for cc in range(c0, c1):
                    j = rr * w + cc
                    if not U8_WALL_MAX < b[j] < U8_FREE_MIN or state[j] == 1 or state[j] == 2:
                        continue
                    if state[j] == 3 or n == n_big:
                        big = True
                        break
                    state[j] = 1
                    queue[n] = j
                    n += 1
                if big:
                    break
        mark = 3 if big or n >= n_big else 2
        for k in range(n):
            state[queue[k]] = mark
    out = np.zeros(len(seeds), np.bool_)
    for k in range(len(seeds)):
        out[k] = state[seeds[k]] == 2
    return out


@njit(cache=True)
def excluded_cells(
    belief, flat, near_bump, failed_until, unreachable_until, step, n_big
):  # pragma: no cover (compiled)
    """Per cell ``flat``: near a bump, failed or walled off at ``step``, or (``n_big`` > 0) in an
    unknown pocket of fewer than ``n_big`` cells."""
    out = np.empty(len(flat), np.bool_)
    bump, failed, walled = near_bump.ravel(), failed_until.ravel(), unreachable_until.ravel()
    for k in range(len(flat)):
        out[k] = bump[flat[k]] or failed[flat[k]] > step or walled[flat[k]] > step
    if n_big > 0:
        out |= _small_pockets(belief, flat, n_big)
    return out


@njit(cache=True)
def frontier_menu(
    belief,
    frontier_flat,
    near_bump,
    failed_until,
    unreachable_until,
    step,
    n_big,
    cum,
    offsets,
    row_y,
    col_x,
    x,
    y,
    heading,
    turn,
    min_cells,
    anchor_r,
    anchor_c,
    anchor_cost,
):  # pragma: no cover (compiled)
    """The frontier part of a menu in one pass: the open frontier cells (not excluded),
    ``(N, 2)``, with their approach costs on ``cum``; their clusters of ``min_cells`` or more
    (cells flat, grouped as :func:`~sfw_gym.navigation.frontiers.cluster_cells` groups them,
    and the groups' bounds); and per cluster the index of its cheapest cell to resolve
    (approach + ``turn`` × heading change + ``anchor_cost`` × the distance to the anchor cell
    ``(anchor_r, anchor_c)`` when ``anchor_r >= 0``)."""
    h, w = belief.shape
    open_flat = frontier_flat[
        ~excluded_cells(
            belief, frontier_flat, near_bump, failed_until, unreachable_until, step, n_big
        )
    ]
    cells = np.empty((len(open_flat), 2), np.int64)
    mask = np.zeros((h, w), np.bool_)
    for k in range(len(open_flat)):
        cells[k, 0] = open_flat[k] // w
        cells[k, 1] = open_flat[k] - cells[k, 0] * w
        mask[cells[k, 0], cells[k, 1]] = True
    open_cost = min_over_offsets(cum, cells, offsets)[0]
    members, bounds = _clusters(mask, open_flat, min_cells)
    cost = open_cost[np.searchsorted(open_flat, members)]
    if turn > 0:
        for k in range(len(members)):
            r = members[k] // w
            c = members[k] - r * w
            bearing = math.atan2(row_y[r] - y, col_x[c] - x) - heading
            cost[k] = cost[k] + turn * abs(wrap_angle_compiled(bearing))
    if anchor_r >= 0 and anchor_cost > 0:
        for k in range(len(members)):
            r = members[k] // w
            c = members[k] - r * w
            dist = math.hypot(row_y[r] - row_y[anchor_r], col_x[c] - col_x[anchor_c])
            cost[k] = cost[k] + anchor_cost * dist
    return cells, open_cost, members, bounds, _first_argmin_per_group(cost, bounds)


@njit(cache=True)
def _first_argmin_per_group(values, bounds):  # pragma: no cover (compiled)
    """Per group ``values[bounds[k]:bounds[k + 1]]``: the index (into ``values``) of its first
    minimum, as ``np.argmin`` picks it."""
    out = np.empty(len(bounds) - 1, np.int64)
    for k in range(len(bounds) - 1):
        best = bounds[k]
        for i in range(bounds[k] + 1, bounds[k + 1]):
            if values[i] < values[best]:
                best = i
        out[k] = best
    return out
