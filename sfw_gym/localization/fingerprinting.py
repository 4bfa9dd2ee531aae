"""Fingerprint localisation on real surveys: building and floor first, then the position.

Methods (:data:`METHODS`), each fit on a training :class:`~sfw_gym.datasets.Fingerprints` and
queried one scan at a time:

- ``1nn``, ``w3nn``, ``w5nn``: the field's baselines: k-NN regression on raw RSSI (not heard →
  −105 dBm), 1 neighbour, or 3 or 5 weighted by inverse distance; building and floor by the same
  neighbours' vote.
- ``sorensen``: weighted 10-NN on the *powed* representation (((RSSI + 104) / 104)², not heard →
  0) with the Sørensen (Bray–Curtis) distance (Torres-Sospedra et al. 2015's best pair):
  building and floor by the neighbours' weighted vote, then the position from the neighbours in
  the chosen building.
- ``gridmaps``: the third paper's approach at scale: building and floor from the ``sorensen``
  vote, then per (building, floor) one GP signal map over every access point heard there (its
  repeated samples averaged per 1 m cell, the kernel shared across access points, so one fit per
  floor), stored as Gaussian gridmaps; a scan's position is the likelihood-weighted mean over the
  cells near the survey. The likelihood sums every heard AP's log density with the GP's variance
  plus one scan's own scatter about the map (measured on the training scans): the paper's Eq.
  12–13 (heard APs weighted by strength, the GP's variance alone) places WiFine's scans at 4.4 m
  mean error, this at 2.7 m.

The measurements that chose these settings are in docs/results/history.md ("Fingerprint
localisation on real data").
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial import cKDTree

from sfw_gym.core.errors import ConfigError
from sfw_gym.datasets import Fingerprints
from sfw_gym.localization.gp import SignalModel
from sfw_gym.localization.gridmaps import GaussianGridmaps
from sfw_gym.localization.mcl import scan_log_likelihood
from sfw_gym.localization.survey import Survey, normalise_rssi

#: Not heard, for the raw-RSSI baselines (below any reading of the public datasets).
RAW_NOT_HEARD_DBM = -105.0
#: The powed representation: readings above this floor, scaled to [0, 1], to this power.
POWED_FLOOR_DBM, POWED_EXPONENT = -104.0, 2.0
SORENSEN_K = 10
#: Tracking's kernel sensor model (KnnLocalizer.log_likelihood).
KERNEL_SIGMA_M, KERNEL_FLOOR, KERNEL_NEIGHBOURS = 1.0, 1e-3, 30
#: Gridmaps: cell size, the survey's averaging cell, how far from the survey cells are kept, and
#: how often an access point must be heard on a floor to get a map there.
GRID_RES_M = 1.0
AVERAGE_CELL_M = 1.0
NEAR_SURVEY_M = 4.0
MIN_HEARD = 3
#: A floor's survey is averaged to at most this many points before its GP is fit (cubic cost).
MAX_GP_POINTS = 1500


@dataclass
class Prediction:
    """Per test scan: position ``(N, 2)``, floor and building (None where the training data has
    none), and the query time per scan."""

    positions: np.ndarray
    floor: np.ndarray | None
    building: np.ndarray | None
    query_s_per_scan: float = 0.0


def raw_features(fp: Fingerprints) -> np.ndarray:
    return fp.filled(RAW_NOT_HEARD_DBM)


def powed_features(fp: Fingerprints) -> np.ndarray:
    scaled = (fp.rssi_dbm - POWED_FLOOR_DBM) / -POWED_FLOOR_DBM
    return np.clip(np.nan_to_num(scaled, nan=0.0), 0.0, 1.0) ** POWED_EXPONENT


def _labels(fp: Fingerprints) -> np.ndarray:
    """One integer per (building, floor) pair (0 where the data has neither)."""
    building = fp.building if fp.building is not None else np.zeros(len(fp), np.int64)
    floor = fp.floor if fp.floor is not None else np.zeros(len(fp), np.int64)
    return building * 1000 + floor


class KnnLocalizer:
    """Weighted k-NN: the neighbours' weighted vote picks building and floor, and their weighted
    mean (within the chosen building) is the position."""

    def __init__(self, k: int, weighted: bool, metric: str, features) -> None:
        self.k, self.weighted, self.metric, self.features = k, weighted, metric, features

    def fit(self, train: Fingerprints) -> KnnLocalizer:
        self.train = train
        self.x = self.features(train)
        self.key = _labels(train)
        self.k_used = min(self.k, len(train))
        if self.metric == "euclidean":
            from sklearn.neighbors import NearestNeighbors  # importing scikit-learn takes a second

            self.index = NearestNeighbors(n_neighbors=self.k_used, algorithm="brute").fit(self.x)
        else:  # Bray–Curtis through what the scan heard (see _sorensen_neighbours)
            self.sums = self.x.sum(1)
            self.x = np.asfortranarray(self.x)  # a scan's heard columns read contiguously
        return self

    def neighbours(self, x: np.ndarray, k: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Distances and indices ``(N, k)`` of each row's ``k`` (default: the method's) nearest
        training scans."""
        k = self.k_used if k is None else min(k, len(self.x))
        if self.metric == "euclidean":
            return self.index.kneighbors(x, n_neighbors=k)
        return _sorensen_neighbours(self.x, self.sums, x, k)

    def _weights(self, dist: np.ndarray) -> np.ndarray:
        return 1.0 / (dist + 1e-6) if self.weighted else np.ones_like(dist)

    def predict_key(self, test: Fingerprints) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(building-floor key, neighbour indices, weights) per test scan."""
        dist, idx = self.neighbours(self.features(test))
        w = self._weights(dist)
        keys = self.key[idx]
        labels = np.unique(keys)
        votes = np.stack([(w * (keys == label)).sum(1) for label in labels], axis=1)
        return labels[np.argmax(votes, axis=1)], idx, w

    def log_likelihood(
        self, scan: Fingerprints, key: int, xy: np.ndarray, sigma_m: float = KERNEL_SIGMA_M
    ) -> np.ndarray:
        """A sensor model for tracking: log p(scan | x) at positions ``xy`` ``(N, 2)`` as a
        kernel density over the training positions on floor ``key``, each of the
        ``KERNEL_NEIGHBOURS`` nearest fingerprints weighted as in :meth:`predict` and spread
        by ``sigma_m``; a floor of ``KERNEL_FLOOR`` of the peak keeps it robust."""
        dist, idx = self.neighbours(self.features(scan), KERNEL_NEIGHBOURS)
        keep = self.key[idx[0]] == key
        w = self._weights(dist[0][keep])
        centres = self.train.positions[idx[0][keep]]
        if not len(w):
            return np.zeros(len(xy))
        d2 = ((xy[:, None, :] - centres[None]) ** 2).sum(-1)
        density = np.exp(-0.5 * d2 / sigma_m**2) @ (w / w.sum())
        return np.log(density + KERNEL_FLOOR)

    def predict(self, test: Fingerprints) -> Prediction:
        start = time.perf_counter()
        key, idx, w = self.predict_key(test)
        same_building = (self.key[idx] // 1000) == (key // 1000)[:, None]
        w = np.where(same_building, w, 0.0)
        positions = np.einsum("nk,nkd->nd", w, self.train.positions[idx]) / w.sum(1)[:, None]
        return _prediction(self.train, positions, key, time.perf_counter() - start, len(test))


def _sorensen_neighbours(train: np.ndarray, sums: np.ndarray, x: np.ndarray, k: int):
    """Bray–Curtis k-NN of non-negative rows: Σ|a − b| / Σ(a + b) = 1 − 2 Σ min(a, b) / Σ(a + b),
    and Σ min(a, b) only runs over what ``b`` heard (a few dozen of hundreds of APs)."""
    dist = np.empty((len(x), k))
    idx = np.empty((len(x), k), np.int64)
    for i, row in enumerate(x):
        heard = np.flatnonzero(row)
        total = sums + row.sum()
        common = np.minimum(train[:, heard], row[heard]).sum(1)
        d = 1.0 - 2.0 * common / np.maximum(total, 1e-12)
        near = np.argpartition(d, k - 1)[:k] if k < len(d) else np.arange(len(d))
        near = near[np.argsort(d[near], kind="stable")]
        dist[i], idx[i] = d[near], near
    return dist, idx


def _prediction(train: Fingerprints, positions, key, seconds: float, n: int) -> Prediction:
    return Prediction(
        positions,
        None if train.floor is None else key % 1000,
        None if train.building is None else key // 1000,
        seconds / max(n, 1),
    )


@dataclass
class FloorMaps:
    """One floor's Gaussian gridmaps over the access points heard there, and the cells near its
    survey (where a scan may be placed)."""

    gridmaps: GaussianGridmaps
    access_points: np.ndarray  # columns of the training data's access points
    allowed: np.ndarray  # (h, w) the gridmaps' cells near the survey
    cells: np.ndarray  # (C, 2) their centres
    mean: np.ndarray = field(repr=False)  # (C, L) at those cells
    variance: np.ndarray = field(repr=False)
    scan_variance: float  # one scan's scatter about the map (normalised units²)

    def log_likelihood(self, rssi_dbm: np.ndarray) -> np.ndarray:
        """The "scan" sensor model (:func:`scan_log_likelihood`) of one scan (its readings over
        all training APs) at every kept cell."""
        z = normalise_rssi(rssi_dbm[self.access_points])
        return scan_log_likelihood(z, self.mean, self.variance, self.scan_variance)


class GridmapLocalizer:
    """The third paper's Gaussian gridmaps per (building, floor); building and floor chosen first
    by the ``sorensen`` vote."""

    def __init__(self, resolution_m: float = GRID_RES_M) -> None:
        if not resolution_m > 0:
            raise ConfigError(f"resolution_m must be > 0, got {resolution_m!r}")
        self.resolution_m = resolution_m
        self.chooser = _sorensen()

    def fit(self, train: Fingerprints) -> GridmapLocalizer:
        self.train = train
        self.chooser.fit(train)
        key = _labels(train)
        self.floors = {int(k): self._fit_floor(train.subset(key == k)) for k in np.unique(key)}
        return self

    def _fit_floor(self, fp: Fingerprints) -> FloorMaps:
        aps = np.flatnonzero(fp.heard.sum(0) >= MIN_HEARD)
        if not len(aps):
            aps = np.flatnonzero(fp.heard.any(0))
        survey = Survey.from_dbm(fp.positions, fp.rssi_dbm[:, aps])
        cell = AVERAGE_CELL_M
        binned = survey.binned(cell)
        while len(binned.positions) > MAX_GP_POINTS:
            cell *= 1.5
            binned = survey.binned(cell)
        model = SignalModel(binned, per_ap=False)
        x0, y0 = fp.positions.min(0) - NEAR_SURVEY_M
        x1, y1 = fp.positions.max(0) + NEAR_SURVEY_M
        maps = GaussianGridmaps.from_model(model, (x0, y0, x1, y1), self.resolution_m)
        centres = maps.cell_centres()
        dist = cKDTree(binned.positions).query(centres, distance_upper_bound=NEAR_SURVEY_M)[0]
        near = np.isfinite(dist)
        mean, var = maps.lookup(centres[near])
        at_scans, _ = maps.lookup(survey.positions)
        heard = survey.signals > 0
        return FloorMaps(
            maps,
            aps,
            near.reshape(maps.shape),
            centres[near],
            np.ascontiguousarray(mean),
            np.ascontiguousarray(var),
            float(np.mean((survey.signals - at_scans)[heard] ** 2)),
        )

    def predict(self, test: Fingerprints) -> Prediction:
        start = time.perf_counter()
        key, _, _ = self.chooser.predict_key(test)
        positions = np.empty((len(test), 2))
        for i, k in enumerate(key):
            floor = self.floors[int(k)]
            ll = floor.log_likelihood(test.rssi_dbm[i])
            w = np.exp(ll - ll.max())
            positions[i] = w @ floor.cells / w.sum()
        return _prediction(self.train, positions, key, time.perf_counter() - start, len(test))


def _sorensen() -> KnnLocalizer:
    return KnnLocalizer(SORENSEN_K, True, "braycurtis", powed_features)


_FACTORIES: dict[str, Callable[[], KnnLocalizer | GridmapLocalizer]] = {
    "1nn": lambda: KnnLocalizer(1, False, "euclidean", raw_features),
    "w3nn": lambda: KnnLocalizer(3, True, "euclidean", raw_features),
    "w5nn": lambda: KnnLocalizer(5, True, "euclidean", raw_features),
    "sorensen": _sorensen,
    "gridmaps": GridmapLocalizer,
}
#: Every method's name; the first of ours that measured best on both datasets is the default.
METHODS = tuple(_FACTORIES)
DEFAULT_METHOD = "sorensen"


def make_localizer(method: str) -> KnnLocalizer | GridmapLocalizer:
    """A fresh, unfitted localiser of ``method`` (one of :data:`METHODS`)."""
    if method not in _FACTORIES:
        raise ConfigError(f"unknown method {method!r}; choose one of {list(METHODS)}")
    return _FACTORIES[method]()
