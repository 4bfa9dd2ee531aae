"""RSSI -> k-value estimation: sliding-window filter, 1-D k-means thresholds, amortised refits.

Per router, each reading becomes a *feature*: the RSSI itself (``"kmeans"``, the paper) or the
RSSI with the log-distance term removed, ``rssi + 10 n log10(d)`` (``"distance_aware"``).
A sliding-window mean smooths the feature, and ``k = #{j : t_j >= feature}`` for descending
thresholds ``t_1 > t_2 > ...`` (so ``k = 0`` above ``t_1``, ``k = K`` at or below ``t_K``).
``K`` reads as "K or more walls". The window is edge-preserving: a reading farther than
``filter_reset_db`` (default 0.7 wall losses) from every reading held restarts it, so a
step in k (the robot crossing a shadow line) is not smeared into features between two levels,
which would be misread and, once fitted, become a spurious level of their own.

Thresholds come from 1-D k-means (a compiled, exact 1-D Lloyd that matches scikit-learn's
KMeans; two deterministic starts, sample quantiles and evenly spaced over the range, the
lower-inertia fit kept; a refit of all routers, merge and thresholds included, is one compiled
call) with ``K + 1`` clusters on the router's samples. With sorted centroids
``C_0 > C_1 > ...``:

1. adjacent centroids closer than ``min_cluster_gap_db`` are merged (size-weighted), so data
   holding fewer levels than ``K + 1`` is not split into spurious k-values, and clusters with
   less than ``min_level_fraction`` of the samples join their nearest neighbour (outliers must
   not become the k = 0 level); the remaining *levels* ``G_0 > ... > G_{m-1}``;
2. the strongest level gets ``k_top = 0`` (the paper) or, with ``k0_level_dbm`` set,
   ``round((k0_level_dbm - G_0) / prior_wall_loss_db)``; each following level one more;
3. thresholds between levels are the midpoints ``(G_{i-1} + G_i) / 2`` (the paper's
   ``t_k = (C_{k-1} + C_k) / 2``); thresholds above ``G_0`` (when ``k_top > 0``) and below
   ``G_{m-1}`` (levels not seen yet) are spaced ``prior_wall_loss_db`` apart, half a wall
   loss from the nearest level; at most ``K`` thresholds are kept.

Before ``refit_min_samples`` samples a prior applies,
``t_j = top - (j - 0.5) * prior_wall_loss_db``,
with ``top`` the strongest level seen so far (the mean of the readings within half a wall loss
of it, restarted at any reading more than half a wall loss above it), or ``k0_level_dbm`` when
calibrated. Refits follow a geometric schedule (the next after ``n * refit_growth`` samples, at
most ``refit_max_interval`` apart) on a bounded, strided subsample, so their cost is amortised;
a refit also comes early once ``refit_min_samples // 2`` samples have fallen more than half a
wall loss outside the fitted centroids (a new level: the robot entered a room behind a wall).

A reading of -100 dBm or less means "not heard": that router gets k = -1 and nothing is stored.
Readings closer than ``min_distance_m`` to their router (near field, where the log-distance
model fails) are classified but neither fitted nor counted by the refit schedule.
"""

from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np
from numba import njit, objmode

from sfw_gym.core.constants import NOT_HEARD_DBM
from sfw_gym.core.errors import ConfigError
from sfw_gym.core.threads import single_threaded_openmp
from sfw_gym.mapping.config import MapperConfig


@njit(cache=True)
def k_from_thresholds(feature, thresholds, n_thr):
    """k-value of one feature: the number of thresholds at or above it (-1 for NaN)."""
    if feature != feature:
        return -1
    k = 0
    for j in range(n_thr):
        if thresholds[j] >= feature:
            k += 1
    return k


#: Where the mapper's kernel finds the thresholds in :meth:`KEstimator._kernel_args`.
KERNEL_ARG_THRESHOLDS, KERNEL_ARG_N_THR = 15, 16


@njit(cache=True)
def add_samples(
    rssi,
    dist,
    distance_aware,
    path_loss_exponent,
    min_distance,
    prior_gap,
    calibrated,
    reset_db,
    ring,
    ring_pos,
    ring_count,
    fit_buf,
    fit_n,
    fit_stride,
    n_seen,
    n_fit_seen,
    next_refit,
    thresholds,
    n_thr,
    fitted,
    prior,
    fit_range,
    novel,
    novel_needed,
    out_feature,
    out_k,
):
    """Add one reading per router; write filtered features and k-values. Returns "refit due"."""
    n_routers = rssi.shape[0]
    window = ring.shape[1]
    cap = fit_buf.shape[1]
    max_k = thresholds.shape[1]
    due = False
    for r in range(n_routers):
        if not rssi[r] > NOT_HEARD_DBM:
            out_feature[r] = np.nan
            out_k[r] = -1
            continue
        f = rssi[r]
        if distance_aware:
            d = max(dist[r], min_distance)
            f += 10.0 * path_loss_exponent * np.log10(d)
        if reset_db > 0.0 and ring_count[r] > 0:
            # A new level (the robot crossed a shadow line): restart the window, so that no
            # feature averages two k-values. "New": farther than reset_db from every reading
            # held (one noisy reading rarely is, when reset_db is well above the noise).
            near = False
            for j in range(ring_count[r]):
                if abs(ring[r, j] - f) <= reset_db:
                    near = True
                    break
            if not near:
                ring_count[r] = 0
                ring_pos[r] = 0
        ring[r, ring_pos[r]] = f
        ring_pos[r] = (ring_pos[r] + 1) % window
        if ring_count[r] < window:
            ring_count[r] += 1
        s = 0.0
        for j in range(ring_count[r]):
            s += ring[r, j]
        f = s / ring_count[r]
        out_feature[r] = f
        n_seen[r] += 1
        if not fitted[r] and not calibrated:
            # Prior: track the strongest level seen (leader clustering with a half-wall band).
            top = prior[r, 0] / prior[r, 1] if prior[r, 1] > 0 else -np.inf
            if f > top + 0.5 * prior_gap:
                prior[r, 0] = f
                prior[r, 1] = 1.0
            elif f > top - 0.5 * prior_gap:
                prior[r, 0] += f
                prior[r, 1] += 1.0
            top = prior[r, 0] / prior[r, 1]
            for j in range(max_k):
                thresholds[r, j] = top - (j + 0.5) * prior_gap
            n_thr[r] = max_k
        out_k[r] = k_from_thresholds(f, thresholds[r], n_thr[r])
        if dist[r] < min_distance:
            continue  # near field: classified, but not used to fit or to trigger refits
        # Strided reservoir for fitting: keep every fit_stride-th sample; halve when full.
        n_fit_seen[r] += 1
        if (n_fit_seen[r] - 1) % fit_stride[r] == 0:
            if fit_n[r] == cap:
                half = 0
                for j in range(0, cap, 2):
                    fit_buf[r, half] = fit_buf[r, j]
                    half += 1
                fit_n[r] = half
                fit_stride[r] *= 2
            if (n_fit_seen[r] - 1) % fit_stride[r] == 0:
                fit_buf[r, fit_n[r]] = f
                fit_n[r] += 1
        if fitted[r]:
            if f > fit_range[r, 0] + 0.5 * prior_gap or f < fit_range[r, 1] - 0.5 * prior_gap:
                novel[r] += 1
                if novel[r] >= novel_needed:
                    next_refit[r] = n_fit_seen[r]
        if n_fit_seen[r] >= next_refit[r]:
            due = True
    return due


@njit(cache=True)
def _merge_sorted(c, w, min_gap, min_fraction):
    """:func:`merge_levels` on centroids already sorted descending (``w`` > 0), compiled."""
    c = c.copy()
    w = w.copy()
    m = c.shape[0]

    def merge(i, m):
        wt = w[i] + w[i + 1]
        c[i] = (c[i] * w[i] + c[i + 1] * w[i + 1]) / wt
        w[i] = wt
        for j in range(i + 1, m - 1):
            c[j] = c[j + 1]
            w[j] = w[j + 1]
        return m - 1

    while m > 1:
        i = 0
        gap = c[0] - c[1]
        for j in range(1, m - 1):
            g = c[j] - c[j + 1]
            if g < gap:
                gap = g
                i = j
        if gap >= min_gap:
            break
        m = merge(i, m)
    total = 0.0
    for j in range(m):
        total += w[j]
    while m > 1:
        i = 0
        for j in range(1, m):
            if w[j] < w[i]:
                i = j
        if w[i] >= min_fraction * total:
            break
        if i == 0:
            m = merge(0, m)
        elif i == m - 1 or c[i - 1] - c[i] <= c[i] - c[i + 1]:
            m = merge(i - 1, m)
        else:
            m = merge(i, m)
    return c[:m].copy()


def merge_levels(
    centroids: np.ndarray, counts: np.ndarray, min_gap: float, min_fraction: float = 0.0
) -> np.ndarray:
    """Sorted (descending) levels after merging close and small clusters.

    First, while the closest adjacent pair is nearer than ``min_gap``, it is merged into its
    size-weighted mean. Then, while the smallest cluster holds less than ``min_fraction`` of the
    samples, it is merged into its nearer neighbour. 0 disables either step.
    """
    c = np.asarray(centroids, dtype=np.float64)
    order = np.argsort(-c)
    w = np.maximum(np.asarray(counts, dtype=np.float64)[order], 1e-12)
    return _merge_sorted(c[order], w, float(min_gap), float(min_fraction))


@njit(cache=True)
def _thresholds(g, max_k, wall_loss_db, k_top):
    """:func:`thresholds_from_levels`, compiled (the same arithmetic)."""
    m = g.shape[0]
    n_below = max(0, max_k - k_top - (m - 1))
    n = min(max_k, k_top + (m - 1) + n_below)
    out = np.empty(n)
    t = 0
    for j in range(1, k_top + 1):
        if t < n:
            out[t] = g[0] + (float(k_top - j) + 0.5) * wall_loss_db
            t += 1
    for j in range(m - 1):
        if t < n:
            out[t] = (g[j] + g[j + 1]) / 2.0
            t += 1
    for j in range(n_below):
        if t < n:
            out[t] = g[m - 1] - (float(j) + 0.5) * wall_loss_db
            t += 1
    return out


def thresholds_from_levels(
    levels: np.ndarray, max_k: int, wall_loss_db: float, k_top: int = 0
) -> np.ndarray:
    """Descending thresholds for descending levels whose first has k-value ``k_top``.

    See the module docstring (step 3). Returns at most ``max_k`` thresholds.
    """
    g = np.asarray(levels, dtype=np.float64).ravel()
    return _thresholds(g, int(max_k), float(wall_loss_db), int(k_top))


# -- 1-D k-means ------------------------------------------------------------------------------
#: Which k-means :func:`fit_levels` (and so :meth:`KEstimator.refit`) uses by default:
#: ``"numba"`` (compiled, exact 1-D Lloyd) or ``"sklearn"`` (the reference; benchmarks only).
FIT_BACKEND = "numba"
#: scikit-learn's KMeans defaults that the fits use: iteration cap and relative tolerance.
KMEANS_MAX_ITER, KMEANS_TOL = 100, 1e-4


@njit(cache=True)
def _farthest(dist, n_empty):
    """scikit-learn's pick for empty clusters, ``argpartition(dist, -n)[:-n-1:-1]`` (numpy's own,
    so ties between equally far points go the same way)."""
    with objmode(far="int64[:]"):
        far = np.argpartition(dist, -n_empty)[: -n_empty - 1 : -1].astype(np.int64)
    return far


@njit(cache=True)
def _small_sum(a):
    """``a.sum()`` as numpy computes it for up to 128 values (pairwise: 8 accumulators)."""
    n = a.shape[0]
    if n < 8:
        res = 0.0
        for i in range(n):
            res += a[i]
        return res
    r = a[:8].copy()
    m = n - n % 8
    for i in range(8, m, 8):
        for j in range(8):
            r[j] += a[i + j]
    res = (r[0] + r[1] + (r[2] + r[3])) + (r[4] + r[5] + (r[6] + r[7]))
    for i in range(m, n):
        res += a[i]
    return res


@njit(cache=True)
def _lloyd_1d(xc, init, max_iter, tol):
    """scikit-learn's ``_kmeans_single_lloyd`` (one thread, unit weights) on centred 1-D data.

    The same arithmetic in the same order, so the same result to the last bit: the E-step's
    distances ``|c|^2 - 2 x c`` (nearest centre, the lowest index on a tie), the M-step's sums in
    data order, empty clusters taking the points farthest from their centres, the stop on
    unchanged labels ("strict") or on a squared centre shift ``<= tol``, then (not strict) a
    last E-step. O(n k) an iteration, no allocation but the labels.

    Returns:
        ``(centres, labels, inertia, n_iter)``.
    """
    k = init.shape[0]
    n = xc.shape[0]
    centers = init.copy()
    new = np.zeros(k)
    c2 = np.empty(k)
    weight = np.zeros(k)
    shift = np.empty(k)
    labels = np.full(n, -1, np.int32)
    labels_old = labels.copy()
    strict = False
    n_iter = 0
    for _ in range(max_iter):
        n_iter += 1
        for j in range(k):
            c2[j] = centers[j] * centers[j]
            new[j] = 0.0
            weight[j] = 0.0
        for i in range(n):
            x = xc[i]
            best = c2[0] - 2.0 * (x * centers[0])
            lab = 0
            for j in range(1, k):
                d = c2[j] - 2.0 * (x * centers[j])
                if d < best:
                    best = d
                    lab = j
            labels[i] = lab
            weight[lab] += 1.0
            new[lab] += x
        n_empty = 0
        for j in range(k):
            if weight[j] == 0.0:
                n_empty += 1
        if n_empty > 0:
            dist = np.empty(n)
            dmax = 0.0
            for i in range(n):
                dist[i] = (xc[i] - centers[labels[i]]) ** 2
                dmax = max(dmax, dist[i])
            if dmax > 0.0:  # else more clusters than distinct values: nothing to relocate
                # The clusters empty now (not those a relocation empties: scikit-learn lists
                # them first; re-checking weights ran past ``far``, out of bounds).
                empty = np.empty(n_empty, np.int64)
                e = 0
                for j in range(k):
                    if weight[j] == 0.0:
                        empty[e] = j
                        e += 1
                far = _farthest(dist, n_empty)
                for e in range(n_empty):
                    j = empty[e]
                    i = far[e]
                    old = labels[i]
                    new[old] -= xc[i]
                    new[j] = xc[i]
                    weight[j] = 1.0
                    weight[old] -= 1.0
        # Average; a cluster still empty goes where the heaviest is (scikit-learn's quirk: its
        # sum, not yet its mean, when that cluster comes later).
        heaviest = np.argmax(weight)
        for j in range(k):
            if weight[j] > 0.0:
                new[j] *= 1.0 / weight[j]
            else:
                new[j] = new[heaviest]
        for j in range(k):
            d = new[j] - centers[j]
            s = math.sqrt(d * d)
            shift[j] = s * s
        centers, new = new, centers
        same = True
        for i in range(n):
            if labels[i] != labels_old[i]:
                same = False
                break
        if same:
            strict = True
            break
        if _small_sum(shift) <= tol:
            break
        labels_old[:] = labels
    if not strict:
        for j in range(k):
            c2[j] = centers[j] * centers[j]
        for i in range(n):
            x = xc[i]
            best = c2[0] - 2.0 * (x * centers[0])
            lab = 0
            for j in range(1, k):
                d = c2[j] - 2.0 * (x * centers[j])
                if d < best:
                    best = d
                    lab = j
            labels[i] = lab
    inertia = 0.0
    for i in range(n):
        d = xc[i] - centers[labels[i]]
        inertia += d * d
    return centers, labels, inertia, n_iter


@njit(cache=True)
def _quantiles_sorted(xs, k):
    """``np.quantile(xs, (arange(k) + 0.5) / k)`` of sorted ``xs``, numpy's rounding included."""
    n = xs.shape[0]
    out = np.empty(k)
    for j in range(k):
        v = (n - 1) * ((j + 0.5) / k)
        if v >= n - 1:
            out[j] = xs[n - 1]
            continue
        lo = int(v)  # v >= 0: floor
        g = v - lo
        a = xs[lo]
        d = xs[lo + 1] - a
        out[j] = xs[lo + 1] - d * (1.0 - g) if g >= 0.5 else a + d * g
    return out


@njit(cache=True)
def _cluster_1d(x, mean, tol, n_clusters_max, max_iter):
    """The two-start k-means of :func:`fit_levels` on ``x`` (``mean``, ``tol``: its mean and
    ``var * tol_rel``, from numpy): ``(centres, counts)``, empty when ``x`` holds fewer than 2
    distinct values."""
    xs = np.sort(x)
    n = xs.shape[0]
    uniq = np.empty(n)
    n_uniq = 0
    for i in range(n):
        if i == 0 or xs[i] != xs[i - 1]:
            uniq[n_uniq] = xs[i]
            n_uniq += 1
    if n_uniq < 2:
        return np.empty(0), np.empty(0, np.int64)
    uniq = uniq[:n_uniq]
    k = min(n_clusters_max, n_uniq)
    q = _quantiles_sorted(xs, k)
    for j in range(1, k):
        if q[j] == q[j - 1]:
            q = _quantiles_sorted(uniq, k)
            break
    # np.linspace(uniq[0], uniq[-1], k)
    step = (uniq[n_uniq - 1] - uniq[0]) / (k - 1)
    spread = np.empty(k)
    for j in range(k):
        spread[j] = j * step + uniq[0]
    spread[k - 1] = uniq[n_uniq - 1]
    xc = x - mean
    best_c, best_l, best_i, _ = _lloyd_1d(xc, q - mean, max_iter, tol)
    c, lab, inertia, _ = _lloyd_1d(xc, spread - mean, max_iter, tol)
    if inertia < best_i:
        best_c, best_l = c, lab
    counts = np.zeros(k, np.int64)
    for i in range(n):
        counts[best_l[i]] += 1
    return best_c + mean, counts


@njit(cache=True)
def _block_sum(a, lo, n):
    """``a[lo:lo + n].sum()`` for ``n <= 128`` as numpy computes it (8 accumulators)."""
    if n < 8:
        res = 0.0
        for i in range(lo, lo + n):
            res += a[i]
        return res
    r0, r1, r2, r3 = a[lo], a[lo + 1], a[lo + 2], a[lo + 3]
    r4, r5, r6, r7 = a[lo + 4], a[lo + 5], a[lo + 6], a[lo + 7]
    m = n - n % 8
    for i in range(lo + 8, lo + m, 8):
        r0 += a[i]
        r1 += a[i + 1]
        r2 += a[i + 2]
        r3 += a[i + 3]
        r4 += a[i + 4]
        r5 += a[i + 5]
        r6 += a[i + 6]
        r7 += a[i + 7]
    res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    for i in range(lo + m, lo + n):
        res += a[i]
    return res


@njit(cache=True)
def _pairwise_sum(a):
    """``a.sum()`` as numpy computes it, to the bit: its pairwise summation (blocks of at most
    128 values, see :func:`_block_sum`; longer runs split in halves rounded down to a multiple
    of 8, the left half's sum plus the right's), evaluated with an explicit stack (a recursive
    compiled function does not survive numba's cache)."""
    n = a.shape[0]
    if n <= 128:
        return _block_sum(a, 0, n)
    node_lo = np.empty(128, np.int64)
    node_n = np.empty(128, np.int64)
    node_stage = np.empty(128, np.int64)
    vals = np.empty(128)
    sp = 1
    vp = 0
    node_lo[0], node_n[0], node_stage[0] = 0, n, 0
    while sp > 0:
        t = sp - 1
        lo, m = node_lo[t], node_n[t]
        if m <= 128:
            vals[vp] = _block_sum(a, lo, m)
            vp += 1
            sp -= 1
            continue
        m2 = m // 2
        m2 -= m2 % 8
        if node_stage[t] == 0:  # left half first
            node_stage[t] = 1
            node_lo[sp], node_n[sp], node_stage[sp] = lo, m2, 0
            sp += 1
        elif node_stage[t] == 1:  # then the right half
            node_stage[t] = 2
            node_lo[sp], node_n[sp], node_stage[sp] = lo + m2, m - m2, 0
            sp += 1
        else:  # both done: left + right
            vals[vp - 2] = vals[vp - 2] + vals[vp - 1]
            vp -= 1
            sp -= 1
    return vals[0]


@njit(cache=True)
def _mean_var(x):
    """``(x.mean(), x.var())`` as numpy computes them (``x`` 1-D contiguous, not empty)."""
    n = x.shape[0]
    mean = _pairwise_sum(x) / n
    sq = np.empty(n)
    for i in range(n):
        d = x[i] - mean
        sq[i] = d * d
    return mean, _pairwise_sum(sq) / n


@njit(cache=True)
def _fit_levels_1d(x, n_clusters_max, min_gap, min_fraction, max_iter, tol_rel):
    """:func:`fit_levels`' numba backend in one compiled call: ``(status, levels, lowest,
    highest)``, status 1 fitted, 0 fewer than 2 distinct values, 2 two kept centroids exactly
    equal (their order in numpy's ``argsort`` is not reproduced here: the caller falls back to
    :func:`merge_levels`)."""
    empty = np.empty(0)
    if x.shape[0] == 0:
        return 0, empty, 0.0, 0.0
    mean, var = _mean_var(x)
    cents, counts = _cluster_1d(x, mean, var * tol_rel, n_clusters_max, max_iter)
    k = cents.shape[0]
    if k == 0:
        return 0, empty, 0.0, 0.0
    # the kept (non-empty) clusters, sorted descending by insertion (unique without ties)
    c = np.empty(k)
    w = np.empty(k)
    m = 0
    for j in range(k):
        if counts[j] > 0:
            v = cents[j]
            cw = float(counts[j])
            i = m
            while i > 0 and c[i - 1] < v:
                c[i] = c[i - 1]
                w[i] = w[i - 1]
                i -= 1
            if i > 0 and c[i - 1] == v:
                return 2, empty, 0.0, 0.0
            c[i] = v
            w[i] = cw
            m += 1
    levels = _merge_sorted(c[:m], w[:m], min_gap, min_fraction)
    return 1, levels, c[m - 1], c[0]


@njit(cache=True)
def _refit_routers(
    force,
    growth_factor,
    max_interval,
    max_k,
    min_gap,
    min_fraction,
    wall_loss_db,
    calibrated,
    k0_level_dbm,
    max_iter,
    tol_rel,
    fit_buf,
    fit_n,
    n_fit_seen,
    next_refit,
    novel,
    thresholds,
    n_thr,
    fit_range,
    fitted,
    fallback,
):
    """:meth:`KEstimator.refit`'s loop over the routers, compiled (numba backend): the schedule,
    the fit, the thresholds. Routers whose fit needs :func:`merge_levels` (tied centroids) are
    scheduled but flagged in ``fallback``, not fitted. Returns ``(n_fitted, n_fallback)``."""
    n_fitted = 0
    n_fallback = 0
    for r in range(fit_n.shape[0]):
        fallback[r] = False
        n_seen = n_fit_seen[r]
        if n_seen == 0 or (not force and n_seen < next_refit[r]):
            continue
        growth = math.ceil(n_seen * (growth_factor - 1.0))
        next_refit[r] = n_seen + max(1, min(growth, max_interval))
        novel[r] = 0
        status, levels, lowest, highest = _fit_levels_1d(
            fit_buf[r, : fit_n[r]], max_k + 1, min_gap, min_fraction, max_iter, tol_rel
        )
        if status == 0:
            continue
        if status == 2:
            fallback[r] = True
            n_fallback += 1
            continue
        k_top = 0
        if calibrated:
            k_top = int(np.rint((k0_level_dbm - levels[0]) / wall_loss_db))
            k_top = min(max(k_top, 0), max_k)
        thr = _thresholds(levels, max_k, wall_loss_db, k_top)
        for j in range(thresholds.shape[1]):
            thresholds[r, j] = thr[j] if j < thr.shape[0] else -np.inf
        n_thr[r] = thr.shape[0]
        fit_range[r, 0] = highest
        fit_range[r, 1] = lowest
        fitted[r] = True
        n_fitted += 1
    return n_fitted, n_fallback


def kmeans_1d(
    data, init, max_iter: int = KMEANS_MAX_ITER, tol: float = KMEANS_TOL
) -> tuple[np.ndarray, np.ndarray, float, int]:
    """Compiled 1-D k-means from the given initial centres: scikit-learn's, to the last bit.

    The same as ``KMeans(len(init), init=init[:, None], n_init=1, max_iter=max_iter,
    tol=tol).fit(data[:, None])`` run single-threaded (see :func:`_lloyd_1d`), at a few
    microseconds per thousand points and iteration where scikit-learn spends ~1 ms a call.

    Returns:
        ``(centres, labels, inertia, n_iter)``, centres in the order of ``init``.
    """
    x = np.ascontiguousarray(data, dtype=np.float64).ravel()
    c0 = np.array(init, dtype=np.float64).ravel()
    if not 1 <= c0.size <= x.size:
        raise ValueError(f"kmeans_1d needs 1 <= len(init) <= len(data), got {c0.size}, {x.size}")
    mean = x.mean()
    c, labels, inertia, n_iter = _lloyd_1d(x - mean, c0 - mean, int(max_iter), x.var() * tol)
    return c + mean, labels, float(inertia), int(n_iter)


_warm = False


def _warm_up_kmeans() -> None:
    """Run every path of the compiled k-means once (the first relocation of an empty cluster
    costs ~70 ms: numba compiles its object-mode block at first use, it is not cached), so the
    first fit that needs it (or ``offline._warm_up``, through the first fit) pays it up front."""
    global _warm
    kmeans_1d([0.0, 1.0, 10.0], [0.0, 5.0, 100.0])  # 100 gets nothing: relocated to 10
    # Each compiled entry point compiles that block anew: the refit's, fit_levels' (and its
    # fallback's) too, with the argument types of their real calls. 6 clusters on these 9 points
    # relocate from the quantile start.
    x = np.array([-69.19, -24.11, -69.09, -68.68, -68.95, -69.7, -23.22, -24.34, -24.56])
    _fit_levels_1d(x, 6, 3.0, 0.1, KMEANS_MAX_ITER, KMEANS_TOL)
    _cluster_1d(x, *_mean_var(x), 6, KMEANS_MAX_ITER)
    i64, one = np.int64, np.ones(1, np.int64)
    _refit_routers(
        True, 1.5, 2000, 5, 3.0, 0.1, 10.0, False, 0.0, KMEANS_MAX_ITER, KMEANS_TOL,
        x[None, :].copy(), one * x.size, one * x.size, np.zeros(1, i64), np.zeros(1, i64),
        np.zeros((1, 5)), np.zeros(1, i64), np.zeros((1, 2)), np.zeros(1, np.bool_),
        np.zeros(1, np.bool_),
    )  # fmt: skip
    _warm = True


def _cluster_sklearn(x: np.ndarray, n_clusters_max: int) -> tuple[np.ndarray, np.ndarray]:
    """The reference for :func:`_cluster_1d`: the same two starts through scikit-learn."""
    from sklearn.cluster import KMeans  # imported here: ~0.5 s that only this path needs
    from sklearn.exceptions import ConvergenceWarning

    uniq = np.unique(x)
    if uniq.size < 2:
        return np.empty(0), np.empty(0, np.int64)
    n_clusters = min(n_clusters_max, uniq.size)
    q = np.quantile(x, (np.arange(n_clusters) + 0.5) / n_clusters)
    if np.unique(q).size < n_clusters:
        q = np.quantile(uniq, (np.arange(n_clusters) + 0.5) / n_clusters)
    spread = np.linspace(uniq[0], uniq[-1], n_clusters)
    best: tuple[Any, np.ndarray] | None = None
    # One thread: the fit is tiny, OpenMP spin-waits cost milliseconds, and a fork stays safe.
    with single_threaded_openmp(), warnings.catch_warnings():
        # Fewer distinct clusters than asked (repeated values) is fine: empty ones are dropped.
        warnings.simplefilter("ignore", ConvergenceWarning)
        for init in (q, spread):
            km = KMeans(
                n_clusters=n_clusters,
                init=init[:, None],
                n_init=1,
                max_iter=KMEANS_MAX_ITER,
                tol=KMEANS_TOL,
            )
            labels = km.fit_predict(x[:, None])
            if best is None or km.inertia_ < best[0].inertia_:
                best = (km, labels)
    assert best is not None
    km, labels = best
    return km.cluster_centers_[:, 0], np.bincount(labels, minlength=n_clusters)


def fit_levels(
    data: np.ndarray,
    max_k: int,
    min_gap_db: float,
    min_fraction: float = 0.0,
    *,
    backend: str | None = None,
):
    """1-D k-means with ``max_k + 1`` clusters on ``data``.

    Two deterministic starts, the better (lower inertia) kept: sample quantiles, which suit
    balanced levels, and evenly spaced over the range, which keeps a dominant level (most
    samples seen from one room) from taking several clusters and leaving two sparse levels to
    share one. The fit is a compiled, exact 1-D Lloyd (:func:`kmeans_1d`; tens of µs where
    scikit-learn's KMeans costs ~1 ms a call); ``backend="sklearn"`` (or the module's
    :data:`FIT_BACKEND`) runs the same starts through scikit-learn, the reference.

    Returns:
        ``(levels, (lowest, highest))``: the merged descending levels and the extreme raw
        centroids, or None when the data has fewer than 2 distinct values.
    """
    backend = FIT_BACKEND if backend is None else backend
    x = np.ascontiguousarray(data, dtype=np.float64).ravel()
    if backend == "numba":
        if not _warm:
            _warm_up_kmeans()
        status, levels, lowest, highest = _fit_levels_1d(
            x, int(max_k) + 1, float(min_gap_db), float(min_fraction), KMEANS_MAX_ITER, KMEANS_TOL
        )
        if status == 1:
            return levels, (float(lowest), float(highest))
        if status == 0:
            return None
        mean, var = _mean_var(x)  # tied centroids: numpy's argsort orders them
        cents, counts = _cluster_1d(x, mean, var * KMEANS_TOL, int(max_k) + 1, KMEANS_MAX_ITER)
    elif backend == "sklearn":
        cents, counts = _cluster_sklearn(x, int(max_k) + 1)
    else:
        raise ConfigError(f"backend must be 'numba' or 'sklearn', got {backend!r}")
    if cents.size == 0:
        return None
    keep = counts > 0
    cents = cents[keep]
    levels = merge_levels(cents, counts[keep], min_gap_db, min_fraction)
    return levels, (float(cents.min()), float(cents.max()))


class KEstimator:
    """Per-router RSSI -> k estimator (see the module docstring for the method).

    Use :meth:`update` (add a reading and get its k-values), or :meth:`add` then
    :meth:`estimate` / :attr:`last_k`.

    Args:
        n_routers: Number of routers R.
        config: Mapper configuration (its k-estimation fields are used).
    """

    def __init__(self, n_routers: int, config: MapperConfig | None = None) -> None:
        if isinstance(n_routers, bool) or not isinstance(n_routers, (int, np.integer)):
            raise ConfigError(f"n_routers must be an int >= 1, got {n_routers!r}")
        if n_routers < 1:
            raise ConfigError(f"n_routers must be an int >= 1, got {n_routers!r}")
        self.config = config if config is not None else MapperConfig()
        if not isinstance(self.config, MapperConfig):
            raise ConfigError(f"config must be a MapperConfig, got {type(self.config).__name__}")
        self.n_routers = n = int(n_routers)
        cfg = self.config
        #: Effective restart distance of the edge-preserving filter (0 = plain sliding mean).
        self.filter_reset_db = (
            0.7 * cfg.prior_wall_loss_db if cfg.filter_reset_db is None else cfg.filter_reset_db
        )
        self._ring = np.zeros((n, cfg.filter_window))
        self._ring_pos = np.zeros(n, np.int64)
        self._ring_count = np.zeros(n, np.int64)
        self._fit_buf = np.zeros((n, cfg.fit_buffer_size + (cfg.fit_buffer_size % 2)))
        self._fit_n = np.zeros(n, np.int64)
        self._fit_stride = np.ones(n, np.int64)
        self._n_seen = np.zeros(n, np.int64)
        self._n_fit_seen = np.zeros(n, np.int64)
        self._next_refit = np.zeros(n, np.int64)
        self._thresholds = np.zeros((n, cfg.max_k))
        self._n_thr = np.zeros(n, np.int64)
        self._fitted = np.zeros(n, np.bool_)
        self._prior = np.zeros((n, 2))
        self._fit_range = np.zeros((n, 2))
        self._novel = np.zeros(n, np.int64)
        self._feature = np.full(n, np.nan)
        self._k = np.full(n, -1, np.int64)
        self._fallback = np.zeros(n, np.bool_)
        self.reset()

    def reset(self) -> None:
        """Forget every sample and fit, back to the prior (in place)."""
        cfg = self.config
        for a in (self._ring, self._ring_pos, self._ring_count, self._fit_buf, self._fit_n):
            a.fill(0)
        for a in (self._n_seen, self._n_fit_seen, self._n_thr, self._prior, self._fit_range):
            a.fill(0)
        self._novel.fill(0)
        self._fit_stride.fill(1)
        self._next_refit.fill(cfg.refit_min_samples)
        self._thresholds.fill(-np.inf)
        self._fitted.fill(False)
        self._feature.fill(np.nan)
        self._k.fill(-1)
        if cfg.k0_level_dbm is not None:
            prior = thresholds_from_levels(
                np.array([cfg.k0_level_dbm]), cfg.max_k, cfg.prior_wall_loss_db
            )
            self._thresholds[:] = prior
            self._n_thr[:] = prior.size
        self.n_refits = 0

    # -- state shared with the mapper's compiled kernel ------------------------------------
    def _kernel_args(self) -> tuple[Any, ...]:
        """The estimator's state, in the order :func:`add_samples` takes it."""
        cfg = self.config
        args = (
            cfg.k_estimator == "distance_aware",
            float(cfg.path_loss_exponent),
            float(cfg.min_distance_m),
            float(cfg.prior_wall_loss_db),
            cfg.k0_level_dbm is not None,
            self.filter_reset_db,
            self._ring,
            self._ring_pos,
            self._ring_count,
            self._fit_buf,
            self._fit_n,
            self._fit_stride,
            self._n_seen,
            self._n_fit_seen,
            self._next_refit,
            self._thresholds,
            self._n_thr,
            self._fitted,
            self._prior,
            self._fit_range,
            self._novel,
            max(2, cfg.refit_min_samples // 2),
        )
        assert (
            args[KERNEL_ARG_THRESHOLDS] is self._thresholds
            and args[KERNEL_ARG_N_THR] is self._n_thr
        )
        return args

    def _check(self, name: str, values) -> np.ndarray:
        a = np.asarray(values, dtype=np.float64)
        if a.shape != (self.n_routers,):
            raise ConfigError(f"{name} must have shape ({self.n_routers},), got {a.shape}")
        if not np.isfinite(a).all():
            raise ConfigError(f"{name} must be finite (use -100 dBm for 'not heard'), got {a}")
        return a

    def add(self, rssi_dbm, distances_m) -> np.ndarray:
        """Add one reading per router, refitting if the schedule says so.

        Args:
            rssi_dbm: ``(R,)`` RSSI in dBm; <= -100 means "not heard".
            distances_m: ``(R,)`` robot-router distances in metres (ignored by ``"kmeans"``).

        Returns:
            ``(R,)`` filtered features (NaN where not heard). The reading's k-values, under the
            thresholds after any refit, are in :attr:`last_k`.
        """
        rssi = self._check("rssi_dbm", rssi_dbm)
        dist = self._check("distances_m", distances_m)
        due = add_samples(rssi, dist, *self._kernel_args(), self._feature, self._k)  # type: ignore[call-arg]  # numba
        if due:
            self.refit()
            self._k[:] = self.estimate(self._feature)
        return self._feature.copy()

    def update(self, rssi_dbm, distances_m) -> np.ndarray:
        """Add one reading per router and return its ``(R,)`` int k-values (-1 not heard)."""
        self.add(rssi_dbm, distances_m)
        return self._k.copy()

    def estimate(self, features) -> np.ndarray:
        """k-values of ``(R,)`` features under the current thresholds (-1 for NaN)."""
        f = np.asarray(features, dtype=np.float64)
        if f.shape != (self.n_routers,):
            raise ConfigError(f"features must have shape ({self.n_routers},), got {f.shape}")
        out = np.full(self.n_routers, -1, np.int64)
        for r in range(self.n_routers):
            out[r] = k_from_thresholds(f[r], self._thresholds[r], self._n_thr[r])
        return out

    @property
    def last_k(self) -> np.ndarray:
        """k-values of the latest reading, ``(R,)`` int, -1 where not heard."""
        return self._k.copy()

    @property
    def n_samples(self) -> np.ndarray:
        """Heard readings so far per router (near-field ones included)."""
        return self._n_seen.copy()

    def thresholds(self, router: int) -> np.ndarray:
        """Current descending thresholds ``t_1 > t_2 > ...`` of one router (feature units)."""
        return self._thresholds[router, : self._n_thr[router]].copy()

    def refit(self, force: bool = False) -> None:
        """Refit every router whose schedule is due (every router with samples if forced)."""
        if FIT_BACKEND != "numba":
            self._refit_python(force)
            return
        if not _warm:
            _warm_up_kmeans()
        cfg = self.config
        n_fitted, n_fallback = _refit_routers(
            bool(force),
            float(cfg.refit_growth),
            int(cfg.refit_max_interval),
            int(cfg.max_k),
            float(cfg.min_cluster_gap_db),
            float(cfg.min_level_fraction),
            float(cfg.prior_wall_loss_db),
            cfg.k0_level_dbm is not None,
            0.0 if cfg.k0_level_dbm is None else float(cfg.k0_level_dbm),
            KMEANS_MAX_ITER,
            KMEANS_TOL,
            self._fit_buf,
            self._fit_n,
            self._n_fit_seen,
            self._next_refit,
            self._novel,
            self._thresholds,
            self._n_thr,
            self._fit_range,
            self._fitted,
            self._fallback,
        )
        self.n_refits += n_fitted
        if n_fallback:  # tied centroids (rare): the Python fit, schedule already advanced
            for r in np.flatnonzero(self._fallback):
                self._fit_router(int(r))

    def _refit_python(self, force: bool = False) -> None:
        """:meth:`refit` router by router in Python (the reference; any :data:`FIT_BACKEND`)."""
        cfg = self.config
        for r in range(self.n_routers):
            n_seen = int(self._n_fit_seen[r])
            if n_seen == 0 or (not force and n_seen < self._next_refit[r]):
                continue
            growth = math.ceil(n_seen * (cfg.refit_growth - 1.0))
            self._next_refit[r] = n_seen + max(1, min(growth, cfg.refit_max_interval))
            self._novel[r] = 0
            self._fit_router(r)

    def _fit_router(self, r: int) -> None:
        """Fit router ``r``'s levels and thresholds through :func:`fit_levels`."""
        cfg = self.config
        data = self._fit_buf[r, : self._fit_n[r]]
        fit = fit_levels(data, cfg.max_k, cfg.min_cluster_gap_db, cfg.min_level_fraction)
        if fit is None:
            return
        levels, (lowest, highest) = fit
        k_top = 0
        if cfg.k0_level_dbm is not None:
            k_top = round((cfg.k0_level_dbm - levels[0]) / cfg.prior_wall_loss_db)
            k_top = min(max(k_top, 0), cfg.max_k)
        thr = thresholds_from_levels(levels, cfg.max_k, cfg.prior_wall_loss_db, k_top)
        self._thresholds[r, :] = -np.inf
        self._thresholds[r, : thr.size] = thr
        self._n_thr[r] = thr.size
        self._fit_range[r] = (highest, lowest)
        self._fitted[r] = True
        self.n_refits += 1
