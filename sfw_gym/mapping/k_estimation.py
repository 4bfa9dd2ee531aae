"""RSSI -> k-value estimation: sliding-window filter, 1-D k-means thresholds, amortised refits.

Per router, each reading becomes a *feature*: the RSSI itself (``"kmeans"``, the paper) or the
RSSI with the log-distance term removed, ``rssi + 10 n log10(d)`` (``"distance_aware"``).
A sliding-window mean smooths the feature. Thresholds ``t_1 > ... > t_K`` come from 1-D k-means
(scikit-learn) with ``K + 1`` clusters: with sorted centroids ``C_0 > ... > C_K``,
``t_j = (C_{j-1} + C_j) / 2``, and ``k = #{j : t_j >= feature}`` (so ``k = 0`` above ``t_1``).
Adjacent centroids closer than ``min_cluster_gap_db`` are merged first (weighted by cluster
size), so data with fewer levels than ``K + 1`` is not split into spurious k-values.

Before ``refit_min_samples`` samples a prior applies: ``t_j = f_max - (j - 0.5) * prior_wall_loss_db``
with ``f_max`` the largest filtered feature so far (the strongest readings are taken as k = 0).
Refits follow a geometric schedule (the next after ``n * refit_growth`` samples, at most
``refit_max_interval`` apart) on a bounded, strided subsample, so their cost is amortised.

A reading of -100 dBm or less means "not heard": that router gets k = -1 and nothing is stored.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from sklearn.cluster import KMeans

from sfw_gym.errors import ConfigError
from sfw_gym.mapping.config import MapperConfig

NOT_HEARD_DBM = -100.0


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


@njit(cache=True)
def add_samples(
    rssi,
    dist,
    distance_aware,
    path_loss_exponent,
    min_distance,
    prior_gap,
    ring,
    ring_pos,
    ring_count,
    fit_buf,
    fit_n,
    fit_stride,
    n_seen,
    next_refit,
    thresholds,
    n_thr,
    fitted,
    max_feature,
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
        ring[r, ring_pos[r]] = f
        ring_pos[r] = (ring_pos[r] + 1) % window
        if ring_count[r] < window:
            ring_count[r] += 1
        s = 0.0
        for j in range(ring_count[r]):
            s += ring[r, j]
        f = s / ring_count[r]
        out_feature[r] = f
        # Strided reservoir for fitting: keep every fit_stride-th sample; halve when full.
        if n_seen[r] % fit_stride[r] == 0:
            if fit_n[r] == cap:
                half = 0
                for j in range(0, cap, 2):
                    fit_buf[r, half] = fit_buf[r, j]
                    half += 1
                fit_n[r] = half
                fit_stride[r] *= 2
            if n_seen[r] % fit_stride[r] == 0:
                fit_buf[r, fit_n[r]] = f
                fit_n[r] += 1
        n_seen[r] += 1
        if not fitted[r]:
            if f > max_feature[r]:
                max_feature[r] = f
                for j in range(max_k):
                    thresholds[r, j] = f - (j + 0.5) * prior_gap
                n_thr[r] = max_k
        out_k[r] = k_from_thresholds(f, thresholds[r], n_thr[r])
        if n_seen[r] >= next_refit[r]:
            due = True
    return due


def thresholds_from_centroids(
    centroids: np.ndarray, counts: np.ndarray, min_gap: float
) -> np.ndarray:
    """Descending thresholds at midpoints of sorted centroids, after merging close ones.

    Args:
        centroids: 1-D cluster centres (any order).
        counts: Cluster sizes (weights for merging), same length.
        min_gap: Adjacent centroids closer than this are merged into their weighted mean,
            closest pair first. 0 disables merging.

    Returns:
        1-D array ``t_1 > t_2 > ...`` of length (number of clusters left) - 1.
    """
    order = np.argsort(-np.asarray(centroids, dtype=np.float64))
    c = list(np.asarray(centroids, dtype=np.float64)[order])
    w = list(np.maximum(np.asarray(counts, dtype=np.float64)[order], 1e-12))
    while len(c) > 1:
        gaps = [c[i] - c[i + 1] for i in range(len(c) - 1)]
        i = int(np.argmin(gaps))
        if gaps[i] >= min_gap:
            break
        wt = w[i] + w[i + 1]
        c[i] = (c[i] * w[i] + c[i + 1] * w[i + 1]) / wt
        w[i] = wt
        del c[i + 1], w[i + 1]
    c_arr = np.asarray(c)
    return (c_arr[:-1] + c_arr[1:]) / 2.0


class KEstimator:
    """Per-router RSSI -> k estimator (see the module docstring for the method).

    Use :meth:`update` (add a reading and get k), or :meth:`add` then :meth:`estimate`.

    Args:
        n_routers: Number of routers R.
        config: Mapper configuration (k-estimation fields are used).
    """

    def __init__(self, n_routers: int, config: MapperConfig | None = None) -> None:
        if isinstance(n_routers, bool) or not isinstance(n_routers, (int, np.integer)):
            raise ConfigError(f"n_routers must be an int >= 1, got {n_routers!r}")
        if n_routers < 1:
            raise ConfigError(f"n_routers must be an int >= 1, got {n_routers!r}")
        self.config = config if config is not None else MapperConfig()
        if not isinstance(self.config, MapperConfig):
            raise ConfigError(f"config must be a MapperConfig, got {type(self.config).__name__}")
        self.n_routers = int(n_routers)
        self.reset()

    def reset(self) -> None:
        """Forget every sample and fit (back to the prior)."""
        cfg, n = self.config, self.n_routers
        self._ring = np.zeros((n, cfg.filter_window))
        self._ring_pos = np.zeros(n, np.int64)
        self._ring_count = np.zeros(n, np.int64)
        self._fit_buf = np.zeros((n, cfg.fit_buffer_size + (cfg.fit_buffer_size % 2)))
        self._fit_n = np.zeros(n, np.int64)
        self._fit_stride = np.ones(n, np.int64)
        self._n_seen = np.zeros(n, np.int64)
        self._next_refit = np.full(n, cfg.refit_min_samples, np.int64)
        self._thresholds = np.full((n, cfg.max_k), -np.inf)
        self._n_thr = np.zeros(n, np.int64)
        self._fitted = np.zeros(n, np.bool_)
        self._max_feature = np.full(n, -np.inf)
        self._feature = np.full(n, np.nan)
        self._k = np.full(n, -1, np.int64)
        self.n_refits = 0

    # -- state shared with the mapper's compiled kernel ------------------------------------
    def _kernel_args(self) -> tuple:
        cfg = self.config
        return (
            cfg.k_estimator == "distance_aware",
            float(cfg.path_loss_exponent),
            float(cfg.min_distance_m),
            float(cfg.prior_wall_loss_db),
            self._ring,
            self._ring_pos,
            self._ring_count,
            self._fit_buf,
            self._fit_n,
            self._fit_stride,
            self._n_seen,
            self._next_refit,
            self._thresholds,
            self._n_thr,
            self._fitted,
            self._max_feature,
        )

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
            ``(R,)`` filtered features (NaN where not heard). The k-values of this reading are
            available from :meth:`estimate` or :attr:`last_k`.
        """
        rssi = self._check("rssi_dbm", rssi_dbm)
        dist = self._check("distances_m", distances_m)
        due = add_samples(rssi, dist, *self._kernel_args(), self._feature, self._k)
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
        """Heard readings so far per router."""
        return self._n_seen.copy()

    def thresholds(self, router: int) -> np.ndarray:
        """Current descending thresholds ``t_1 > t_2 > ...`` of one router (feature units)."""
        return self._thresholds[router, : self._n_thr[router]].copy()

    def refit(self, force: bool = False) -> None:
        """Refit the thresholds of every router whose schedule is due (all heard ones if forced)."""
        cfg = self.config
        for r in range(self.n_routers):
            n_seen = int(self._n_seen[r])
            if n_seen == 0 or (not force and n_seen < self._next_refit[r]):
                continue
            growth = math.ceil(n_seen * (cfg.refit_growth - 1.0))
            self._next_refit[r] = n_seen + max(1, min(growth, cfg.refit_max_interval))
            if n_seen < cfg.refit_min_samples and not force:
                continue
            data = self._fit_buf[r, : self._fit_n[r]]
            thr = fit_thresholds(data, cfg.max_k, cfg.min_cluster_gap_db)
            if thr is None:
                continue
            self._thresholds[r, :] = -np.inf
            self._thresholds[r, : thr.size] = thr
            self._n_thr[r] = thr.size
            self._fitted[r] = True
            self.n_refits += 1


def fit_thresholds(data: np.ndarray, max_k: int, min_gap_db: float) -> np.ndarray | None:
    """Thresholds from 1-D k-means with ``max_k + 1`` clusters (None if < 2 distinct values).

    The initial centroids are the data's quantiles at ``(i + 0.5) / (max_k + 1)``, so the fit
    is deterministic.
    """
    x = np.asarray(data, dtype=np.float64)
    uniq = np.unique(x)
    if uniq.size < 2:
        return None
    n_clusters = min(max_k + 1, uniq.size)
    init = np.quantile(x, (np.arange(n_clusters) + 0.5) / n_clusters)
    if np.unique(init).size < n_clusters:
        init = np.quantile(uniq, (np.arange(n_clusters) + 0.5) / n_clusters)
    km = KMeans(n_clusters=n_clusters, init=init[:, None], n_init=1, max_iter=100)
    labels = km.fit_predict(x[:, None])
    counts = np.bincount(labels, minlength=n_clusters)
    keep = counts > 0
    return thresholds_from_centroids(km.cluster_centers_[keep, 0], counts[keep], min_gap_db)
