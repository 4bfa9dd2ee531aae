"""Map and k-value metrics: the paper's (Kim et al., arXiv 2408.07757, Eq. 8-16) and ours.

Maps are uint8 grids in the paper's convention: 0 = wall, 255 = free, 127 = unknown (ground
truth: 127 = outside the plan). Estimated maps may be graded; every metric classifies them by
thirds (:func:`sfw_gym.mapping.grid.belief_classes`): ``<= 84`` wall, ``>= 171`` free, else unknown.

What we settled where the paper is ambiguous:

- *k-value accuracy* (Eq. 8): correct / compared, over samples where both values are defined
  (a router that was not heard, k < 0, is left out). An estimator capped at K reports K for
  "K or more walls" (the paper's rule); pass ``max_k=K`` to compare with ``min(k_true, K)``.
- *Paper IoU* (Eq. 9-12): over the cells known (free or wall) in **both** maps, the
  intersection is the cells where both agree on the class and the union is all of those cells.
  It ignores unexplored cells, so a map that only ever marks correct free cells scores 1.0;
  hence the free-space IoU, wall precision and interior-wall recall below.
- *Paper MSE* (Eq. 13-16): the mean of ``((est - truth) / 255)^2`` (raw uint8 values, so graded
  confidences count) over the same cells known in both maps; 0 is perfect, 1 the worst.

Functions return ``nan`` when their denominator is empty.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from sfw_gym.core.errors import ConfigError
from sfw_gym.mapping.grid import belief_classes

__all__ = [
    "coverage",
    "entropy_bits",
    "evaluate_map",
    "free_iou",
    "interior_wall_cells",
    "interior_wall_recall",
    "k_value_accuracy",
    "map_iou",
    "map_mse",
    "wall_precision",
]

# Axes along which a wall cell is tested for free space on both sides.
_AXES = ((0, 1), (1, 0), (1, 1), (1, -1))


def _pair(est, truth) -> tuple[np.ndarray, np.ndarray]:
    e = np.asarray(est)
    t = np.asarray(truth)
    if e.shape != t.shape or e.ndim != 2:
        raise ConfigError(f"est and truth must be 2-D maps of one shape, got {e.shape}, {t.shape}")
    return e, t


def _ratio(num: float | np.integer, den: float | np.integer) -> float:
    return float(num) / float(den) if den else float("nan")


def k_value_accuracy(k_est, k_true, max_k: int | None = None) -> float:
    """Fraction of k-values estimated exactly (paper Eq. 8).

    Args:
        k_est: Estimated k-values, any shape; negative = undefined (router not heard).
        k_true: True k-values, same shape; negative = undefined.
        max_k: The estimator's largest output K, or None. The paper's rule reads K as
            "K or more walls", so with ``max_k`` the truth is compared as ``min(k_true, K)``:
            an estimate of K is right wherever K or more walls lie between. None compares with
            the true k as it is (an estimator capped at K is then wrong wherever k > K).

    Returns:
        ``#(k_est == k_true) / #(both defined)``; nan if nothing is comparable.
    """
    e = np.asarray(k_est)
    t = np.asarray(k_true)
    if e.shape != t.shape:
        raise ConfigError(f"k_est and k_true must have one shape, got {e.shape}, {t.shape}")
    if max_k is not None:
        if isinstance(max_k, bool) or not isinstance(max_k, (int, np.integer)) or max_k < 0:
            raise ConfigError(f"max_k must be None or an int >= 0, got {max_k!r}")
        t = np.where(t >= 0, np.minimum(t, max_k), t)
    valid = (e >= 0) & (t >= 0)
    return _ratio(np.count_nonzero((e == t) & valid), np.count_nonzero(valid))


def _known_both(e: np.ndarray, t: np.ndarray):
    ef, ew, _ = belief_classes(e)
    tf, tw, _ = belief_classes(t)
    both = (ew | ef) & (tw | tf)
    return both, ew, ef, tw, tf


def map_iou(est_u8, truth_u8) -> float:
    """Paper IoU (Eq. 9-12): class agreement over the cells known in both maps.

    Args:
        est_u8: Estimated uint8 map (graded allowed).
        truth_u8: Ground-truth uint8 map (0 wall, 255 free, 127 outside).

    Returns:
        ``#(known in both and same class) / #(known in both)``.
    """
    e, t = _pair(est_u8, truth_u8)
    both, ew, ef, tw, tf = _known_both(e, t)
    agree = both & (ew == tw) & (ef == tf)
    return _ratio(np.count_nonzero(agree), np.count_nonzero(both))


def map_mse(est_u8, truth_u8) -> float:
    """Paper MSE (Eq. 13-16): mean of ``((est - truth) / 255)^2`` over cells known in both maps."""
    e, t = _pair(est_u8, truth_u8)
    both = _known_both(e, t)[0]
    if not both.any():
        return float("nan")
    diff = (e[both].astype(np.float64) - t[both].astype(np.float64)) / 255.0
    return float(np.mean(diff * diff))


def coverage(est_u8, truth_u8) -> float:
    """Explored ratio: fraction of ground-truth free cells the map classifies (free or wall)."""
    e, t = _pair(est_u8, truth_u8)
    ef, ew, _ = belief_classes(e)
    tf = belief_classes(t)[0]
    return _ratio(np.count_nonzero(tf & (ew | ef)), np.count_nonzero(tf))


def free_iou(est_u8, truth_u8) -> float:
    """Free-space IoU over the whole grid: ``|F_est & F_true| / |F_est | F_true|``.

    Unexplored true free cells lower it (they are in the union only), and so do estimated free
    cells outside the plan or on walls.
    """
    e, t = _pair(est_u8, truth_u8)
    ef = belief_classes(e)[0]
    tf = belief_classes(t)[0]
    return _ratio(np.count_nonzero(ef & tf), np.count_nonzero(ef | tf))


def _check_tol(tolerance_cells: float) -> float:
    tol = float(tolerance_cells)
    if not np.isfinite(tol) or tol < 0:
        raise ConfigError(f"tolerance_cells must be finite and >= 0, got {tolerance_cells!r}")
    return tol


def _distance_to(mask: np.ndarray) -> np.ndarray:
    """Euclidean distance (cells) from every cell to the nearest True cell of ``mask``."""
    if not mask.any():
        return np.full(mask.shape, np.inf)
    return ndimage.distance_transform_edt(~mask)


def wall_precision(est_u8, truth_u8, tolerance_cells: float = 2) -> float:
    """Fraction of estimated wall cells within ``tolerance_cells`` of a true wall cell.

    Distances are Euclidean between cell centres, in cells. nan if the map has no wall cell.
    """
    e, t = _pair(est_u8, truth_u8)
    tol = _check_tol(tolerance_cells)
    ew = belief_classes(e)[1]
    tw = belief_classes(t)[1]
    if not ew.any():
        return float("nan")
    dist = _distance_to(tw)
    return _ratio(np.count_nonzero(dist[ew] <= tol), np.count_nonzero(ew))


def _shift(a: np.ndarray, dr: int, dc: int, fill: bool = False) -> np.ndarray:
    """``out[i, j] = a[i + dr, j + dc]`` (``fill`` beyond the edges)."""
    out = np.full(a.shape, fill, dtype=a.dtype)
    h, w = a.shape
    if abs(dr) >= h or abs(dc) >= w:
        return out
    src_r = slice(max(dr, 0), h + min(dr, 0))
    dst_r = slice(max(-dr, 0), h + min(-dr, 0))
    src_c = slice(max(dc, 0), w + min(dc, 0))
    dst_c = slice(max(-dc, 0), w + min(-dc, 0))
    out[dst_r, dst_c] = a[src_r, src_c]
    return out


def interior_wall_cells(truth_u8, max_thickness_cells: int = 8) -> np.ndarray:
    """True wall cells that separate two free regions.

    A wall cell is *interior* if, along at least one of four axes (row, column, both
    diagonals), walking from it in both directions through wall cells only, a free cell is
    reached on **both** sides within ``max_thickness_cells`` steps. Outer walls (free on one
    side, outside on the other) are not interior; a partition wall between two rooms is, as is
    the wall around a door opening.

    Args:
        truth_u8: Ground-truth uint8 map (0 wall, 255 free, 127 outside).
        max_thickness_cells: Longest walk through wall cells on each side.

    Returns:
        Boolean mask of interior wall cells.
    """
    t = np.asarray(truth_u8)
    if t.ndim != 2:
        raise ConfigError(f"truth_u8 must be a 2-D map, got shape {t.shape}")
    if isinstance(max_thickness_cells, bool) or int(max_thickness_cells) < 1:
        raise ConfigError(f"max_thickness_cells must be an int >= 1, got {max_thickness_cells!r}")
    free, wall, _ = belief_classes(t)
    result = np.zeros(t.shape, np.bool_)
    for dr, dc in _AXES:
        sides = []
        for sign in (1, -1):
            reach = np.zeros(t.shape, np.bool_)
            through_wall = np.ones(t.shape, np.bool_)
            for s in range(1, int(max_thickness_cells) + 1):
                reach |= through_wall & _shift(free, sign * s * dr, sign * s * dc)
                through_wall &= _shift(wall, sign * s * dr, sign * s * dc)
            sides.append(reach)
        result |= wall & sides[0] & sides[1]
    return result


def interior_wall_recall(
    est_u8, truth_u8, tolerance_cells: float = 2, max_thickness_cells: int = 8
) -> float:
    """Fraction of interior true wall cells with an estimated wall within ``tolerance_cells``.

    Interior wall cells are defined by :func:`interior_wall_cells`; distances are Euclidean, in
    cells. nan if the ground truth has no interior wall.
    """
    e, t = _pair(est_u8, truth_u8)
    tol = _check_tol(tolerance_cells)
    interior = interior_wall_cells(t, max_thickness_cells)
    if not interior.any():
        return float("nan")
    dist = _distance_to(belief_classes(e)[1])
    return _ratio(np.count_nonzero(dist[interior] <= tol), np.count_nonzero(interior))


def entropy_bits(probability) -> float:
    """Total binary entropy (bits) of a map of P(occupied) values."""
    p = np.clip(np.asarray(probability, dtype=np.float64), 1e-12, 1.0 - 1e-12)
    return float(-(p * np.log2(p) + (1.0 - p) * np.log2(1.0 - p)).sum())


def evaluate_map(est_u8, truth_u8, tolerance_cells: float = 2) -> dict[str, float]:
    """All map metrics at once: paper IoU and MSE, coverage, free IoU, wall precision/recall."""
    return {
        "paper_iou": map_iou(est_u8, truth_u8),
        "paper_mse": map_mse(est_u8, truth_u8),
        "coverage": coverage(est_u8, truth_u8),
        "free_iou": free_iou(est_u8, truth_u8),
        "wall_precision": wall_precision(est_u8, truth_u8, tolerance_cells),
        "interior_wall_recall": interior_wall_recall(est_u8, truth_u8, tolerance_cells),
    }
