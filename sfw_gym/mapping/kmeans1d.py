"""A compiled 1-D k-means that is scikit-learn's ``KMeans``, to the last bit, without its ~1 ms
of per-call overhead (the thresholds of :mod:`sfw_gym.mapping.k_estimation` are refitted often,
on a few hundred to a few thousand values).

:func:`kmeans_1d` runs Lloyd's iterations from given starts exactly as scikit-learn's
single-threaded Lloyd does (its centring on the mean, its relative tolerance, its relocation of
empty clusters to the farthest points); :func:`mean_var` and the pairwise sums reproduce numpy's
summation order, so the results are bit-identical (``tests/mapping/test_k_estimation.py``).
:func:`cluster_sklearn` is the same fit through scikit-learn: the reference.
"""

from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np
from numba import njit, objmode

from sfw_gym.core.threads import single_threaded_openmp

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
def _nearest(x, centers, c2):
    """The centre nearest ``x`` as scikit-learn finds it: least ``c² − 2xc``, first of ties."""
    best = c2[0] - 2.0 * (x * centers[0])
    lab = 0
    for j in range(1, centers.shape[0]):
        d = c2[j] - 2.0 * (x * centers[j])
        if d < best:
            best = d
            lab = j
    return lab


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
            lab = _nearest(x, centers, c2)
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
            labels[i] = _nearest(xc[i], centers, c2)
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
def cluster_1d(x, mean, tol, n_clusters_max, max_iter):
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
def mean_var(x):
    """``(x.mean(), x.var())`` as numpy computes them (``x`` 1-D contiguous, not empty)."""
    n = x.shape[0]
    mean = _pairwise_sum(x) / n
    sq = np.empty(n)
    for i in range(n):
        d = x[i] - mean
        sq[i] = d * d
    return mean, _pairwise_sum(sq) / n


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


def cluster_sklearn(x: np.ndarray, n_clusters_max: int) -> tuple[np.ndarray, np.ndarray]:
    """The reference for :func:`cluster_1d`: the same two starts through scikit-learn."""
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
