"""Frontiers and hidden rooms of a belief map (map analysis for exploration).

A frontier is an unknown cell 8-adjacent to a believed-free cell of the thresholded belief;
frontier cells are grouped into 8-connected clusters (:func:`scipy.ndimage.label`). A hidden
room is a room-deep unknown pocket inside the explored extent: a room whose doorway the map
closed has no frontier at all.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
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
    depth = ndimage.distance_transform_edt(unknown & inside)
    return np.where(depth >= min_depth_cells, depth, 0.0)


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
    labels, n = ndimage.label(mask, structure=EIGHT_CONNECTED)
    if n == 0:
        return []
    rows, cols = np.nonzero(labels)
    lab = labels[rows, cols]
    sizes = np.bincount(lab, minlength=n + 1)
    keep = sizes[lab] >= min_size_cells
    rows, cols, lab = rows[keep], cols[keep], lab[keep]
    if not len(lab):
        return []
    order = np.argsort(lab, kind="stable")
    rows, cols, lab = rows[order], cols[order], lab[order]
    starts = np.flatnonzero(np.r_[True, lab[1:] != lab[:-1]])
    ends = np.r_[starts[1:], len(lab)]
    out = []
    for a, b in zip(starts, ends, strict=True):
        cells = np.stack([rows[a:b], cols[a:b]], axis=1)
        out.append(
            Frontier(cells, (float(rows[a:b].sum() / (b - a)), float(cols[a:b].sum() / (b - a))))
        )
    out.sort(key=lambda f: -f.size)
    return out
