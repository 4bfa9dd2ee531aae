"""Frontiers and hidden rooms of a belief map (map analysis for exploration).

A frontier is an unknown cell 8-adjacent to a believed-free cell of the thresholded belief;
frontier cells are grouped into 8-connected clusters (:func:`scipy.ndimage.label`). A hidden
room is a room-deep unknown pocket inside the explored extent: a room whose doorway the map
closed has no frontier at all.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit
from scipy import ndimage

from sfw_gym.navigation.planning import belief_classes

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
            i = members[head]
            head += 1
            r = i // w
            c = i - r * w
            for rr in range(max(r - 1, 0), min(r + 2, h)):
                for cc in range(max(c - 1, 0), min(c + 2, w)):
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
