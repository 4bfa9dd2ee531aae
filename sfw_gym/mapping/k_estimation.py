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
from typing import Any

import numpy as np
from numba import njit

from sfw_gym.core.constants import NOT_HEARD_DBM
from sfw_gym.core.errors import ConfigError
from sfw_gym.mapping.config import MapperConfig
from sfw_gym.mapping.kmeans1d import (
    KMEANS_MAX_ITER,
    KMEANS_TOL,
    cluster_1d,
    cluster_sklearn,
    kmeans_1d,
    mean_var,
)


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


@njit(cache=True)
def _fit_levels_1d(x, n_clusters_max, min_gap, min_fraction, max_iter, tol_rel):
    """:func:`fit_levels`' numba backend in one compiled call: ``(status, levels, lowest,
    highest)``, status 1 fitted, 0 fewer than 2 distinct values, 2 two kept centroids exactly
    equal (their order in numpy's ``argsort`` is not reproduced here: the caller falls back to
    :func:`merge_levels`)."""
    empty = np.empty(0)
    if x.shape[0] == 0:
        return 0, empty, 0.0, 0.0
    mean, var = mean_var(x)
    cents, counts = cluster_1d(x, mean, var * tol_rel, n_clusters_max, max_iter)
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
    mean, var = mean_var(x)
    cluster_1d(x, mean, var, 6, KMEANS_MAX_ITER)
    i64, one = np.int64, np.ones(1, np.int64)
    _refit_routers(
        True, 1.5, 2000, 5, 3.0, 0.1, 10.0, False, 0.0, KMEANS_MAX_ITER, KMEANS_TOL,
        x[None, :].copy(), one * x.size, one * x.size, np.zeros(1, i64), np.zeros(1, i64),
        np.zeros((1, 5)), np.zeros(1, i64), np.zeros((1, 2)), np.zeros(1, np.bool_),
        np.zeros(1, np.bool_),
    )  # fmt: skip
    _warm = True


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
        mean, var = mean_var(x)  # tied centroids: numpy's argsort orders them
        cents, counts = cluster_1d(x, mean, var * KMEANS_TOL, int(max_k) + 1, KMEANS_MAX_ITER)
    elif backend == "sklearn":
        cents, counts = cluster_sklearn(x, int(max_k) + 1)
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
