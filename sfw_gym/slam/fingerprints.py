"""Fingerprint similarity: how alike two places sound.

A fingerprint is a vector of RSSI (dBm) per access point, ``NaN`` where the AP was not heard.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree


def cosine_similarity(f_i: np.ndarray, f_j: np.ndarray) -> np.ndarray:
    """The paper's Eq. 2: the products over the APs both heard, divided by the norms of each
    fingerprint over all it heard; 0 when they share no AP. ``f_i``, ``f_j``: ``(..., L)``,
    broadcast against each other."""
    a, b = np.asarray(f_i, np.float64), np.asarray(f_j, np.float64)
    common = ~np.isnan(a) & ~np.isnan(b)
    dot = np.where(common, np.nan_to_num(a) * np.nan_to_num(b), 0.0).sum(axis=-1)
    norm_a = np.sqrt(np.nansum(a * a, axis=-1))
    norm_b = np.sqrt(np.nansum(b * b, axis=-1))
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where((norm_a > 0) & (norm_b > 0), dot / (norm_a * norm_b), 0.0)


def kernel_similarity(f_i: np.ndarray, f_j: np.ndarray, sigma_db: float = 6.0) -> np.ndarray:
    """A sharper variant: the mean over the common APs of ``exp(-Δ² / 2σ²)`` (Δ the RSSI
    difference in dB) times the share of the APs either heard that both heard. With raw dBm
    the cosine of Eq. 2 is near 1 wherever the same APs are heard; this falls off with distance."""
    a, b = np.asarray(f_i, np.float64), np.asarray(f_j, np.float64)
    heard_a, heard_b = ~np.isnan(a), ~np.isnan(b)
    common = heard_a & heard_b
    n_common = common.sum(axis=-1)
    n_any = (heard_a | heard_b).sum(axis=-1)
    delta = np.where(common, np.nan_to_num(a) - np.nan_to_num(b), 0.0)
    kernel = np.where(common, np.exp(-(delta**2) / (2.0 * sigma_db**2)), 0.0).sum(axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(n_common > 0, kernel / n_common * (n_common / n_any), 0.0)


def closure_candidates(
    fingerprints: np.ndarray,
    travelled_m: np.ndarray,
    *,
    min_travel_m: float,
    radius_db: float,
    not_heard_dbm: float = -100.0,
) -> np.ndarray:
    """Pairs ``(i, j)``, ``i < j``, of fingerprints ``(N, L)`` (NaN: not heard) within
    ``radius_db`` of each other (Euclidean over the APs, a not-heard AP counted at
    ``not_heard_dbm``), found with a KD-tree instead of comparing all pairs, whose poses lie at
    least ``min_travel_m`` apart along the path (``travelled_m``: the odometry distance so far
    at each pose): the candidates for radio loop closures, to be scored by a similarity."""
    f = np.nan_to_num(np.asarray(fingerprints, np.float64), nan=not_heard_dbm)
    pairs = cKDTree(f).query_pairs(radius_db, output_type="ndarray")
    if not len(pairs):
        return np.zeros((0, 2), np.int64)
    pairs = np.sort(pairs, axis=1)
    along = np.asarray(travelled_m, np.float64)
    far = np.abs(along[pairs[:, 1]] - along[pairs[:, 0]]) >= min_travel_m
    out = pairs[far]
    return out[np.lexsort((out[:, 1], out[:, 0]))]
