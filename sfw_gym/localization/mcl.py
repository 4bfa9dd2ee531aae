"""WiFi Monte-Carlo localisation on Gaussian gridmaps (the paper's Sec. II-B): an odometry motion
model, the Eq. 12–13 sensor model, low-variance resampling, global localisation by sampling the
likelihood gridmap (Alg. 1), and recovery from a kidnapping by injecting such samples when the
average likelihood collapses (augmented MCL). Vectorised over particles."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from sfw_gym.core.angles import wrap_angle
from sfw_gym.core.config import Config, setting
from sfw_gym.core.errors import ConfigError
from sfw_gym.localization.gp import SignalModel
from sfw_gym.localization.gridmaps import GaussianGridmaps
from sfw_gym.localization.survey import normalise_rssi

_LOG_2PI = float(np.log(2 * np.pi))


@dataclass(frozen=True)
class MclConfig(Config):
    """Particles, motion noise, resampling and recovery."""

    particles: int = setting(1000, integer=True, ge=1, le=10**7)
    translation_noise: float = setting(0.1, ge=0.0, le=10.0)  # std per metre driven
    rotation_noise: float = setting(0.05, ge=0.0, le=10.0)  # std (rad) per step
    resample_ess: float = setting(0.5, gt=0.0, le=1.0)  # resample below this share of P
    slow_rate: float = setting(0.01, ge=0.0, le=1.0)  # augmented MCL's long-term average
    fast_rate: float = setting(0.3, ge=0.0, le=1.0)  # … and short-term average
    # the sensor model: "paper" (Eq. 12–13) or "scan" (scan_log_likelihood, with this variance
    # of one scan's reading about the map, in normalised units²)
    sensor: str = setting("paper", choices=("paper", "scan"))
    scan_variance: float = setting(0.0, ge=0.0, le=1.0)


def log_likelihood(z: np.ndarray, mean: np.ndarray, var: np.ndarray) -> np.ndarray:
    """Eq. 12–13 in logs: Σ_j λ_j log N(z_j | M_j, V_j), λ_j = z_j / Σ z; ``z`` ``(L,)``
    normalised, ``mean``/``var`` ``(N, L)``; an AP not heard (z_j = 0) weighs nothing."""
    total = float(z.sum())
    if total <= 0:
        return np.zeros(len(mean))
    lam = z / total
    var = np.maximum(var, 1e-9)
    return -0.5 * (((z - mean) ** 2 / var + np.log(var) + _LOG_2PI) @ lam)


def scan_log_likelihood(
    z: np.ndarray, mean: np.ndarray, var: np.ndarray, scan_variance: float
) -> np.ndarray:
    """Σ_j log N(z_j | M_j, V_j + σ_s²) over the APs heard (z_j > 0), each counted once: a map
    fit on averaged samples predicts their mean, and one scan scatters about it by σ_s."""
    heard = np.flatnonzero(z)
    var = np.maximum(var[:, heard], 1e-9) + scan_variance
    return -0.5 * ((z[heard] - mean[:, heard]) ** 2 / var + np.log(var) + _LOG_2PI).sum(1)


def low_variance_indices(weights: np.ndarray, n: int, rng: np.random.Generator) -> np.ndarray:
    """The low-variance (systematic) resampler: ``n`` indices drawn by ``weights`` (sum 1)."""
    positions = rng.uniform(0.0, 1.0 / n) + np.arange(n) / n
    cumulative = np.cumsum(weights)
    cumulative[-1] = 1.0
    return np.searchsorted(cumulative, positions, side="left")


class WifiMCL:
    """A particle filter over poses ``(x, y, θ)`` on ``gridmaps``.

    Args:
        gridmaps: The signal maps.
        config: Particles and noise.
        rng: All randomness (pass the env's ``np_random``).
        allowed: Optional ``(h, w)`` mask of the cells a robot can be in (free space).
        direct: Optional GP model: the sensor model predicts each particle's signals with it
            (Eqs. 8–9, the paper's baseline) instead of reading the gridmaps; global
            localisation still samples the gridmaps (Alg. 1).
    """

    def __init__(
        self,
        gridmaps: GaussianGridmaps,
        config: MclConfig | None = None,
        rng: np.random.Generator | None = None,
        allowed: np.ndarray | None = None,
        direct: SignalModel | None = None,
    ) -> None:
        self.maps = gridmaps
        self._predict = direct.predict if direct is not None else gridmaps.lookup
        self.config = config or MclConfig()
        self.rng = rng if rng is not None else np.random.default_rng()
        if allowed is not None and np.shape(allowed) != gridmaps.shape:
            raise ConfigError(f"allowed must have the gridmaps' shape {gridmaps.shape}")
        self.allowed = None if allowed is None else np.asarray(allowed, bool).ravel()
        n = self.config.particles
        self.particles = np.zeros((n, 3))
        self.weights = np.full(n, 1.0 / n)
        self._w_slow = self._w_fast = 0.0

    # -- initialisation --------------------------------------------------------------------------
    def global_init(self, rssi_dbm: np.ndarray) -> None:
        """Particles drawn from the likelihood gridmap of one reading (Alg. 1)."""
        self.particles = self.sample_from_reading(rssi_dbm, self.config.particles)
        self.weights.fill(1.0 / self.config.particles)

    def sample_from_reading(self, rssi_dbm: np.ndarray, n: int) -> np.ndarray:
        """Alg. 1: ``n`` poses from the cells' likelihoods of ``rssi_dbm``, uniform within a
        cell, any heading."""
        centres = self.maps.cell_centres()
        mean, var = self.maps.lookup(centres)
        log_l = self._log_likelihood(normalise_rssi(rssi_dbm), mean, var)
        if self.allowed is not None:
            log_l = np.where(self.allowed, log_l, -np.inf)
        w = np.exp(log_l - log_l.max())
        cells = low_variance_indices(w / w.sum(), n, self.rng)
        r = self.maps.resolution_m
        xy = centres[cells] + self.rng.uniform(-r / 2, r / 2, (n, 2))
        return np.column_stack([xy, self.rng.uniform(-np.pi, np.pi, n)])

    def init_at(self, pose: np.ndarray, spread_m: float = 0.1, spread_rad: float = 0.05) -> None:
        """Particles around a known pose (tracking)."""
        n = self.config.particles
        noise = self.rng.normal(0.0, 1.0, (n, 3)) * [spread_m, spread_m, spread_rad]
        self.particles = np.asarray(pose, np.float64) + noise
        self.weights.fill(1.0 / n)

    # -- the filter ------------------------------------------------------------------------------
    def predict(self, delta: Sequence[float] | np.ndarray) -> None:
        """Move every particle by an odometry increment ``(dx, dy, dθ)`` in the robot's frame,
        with noise proportional to it."""
        dx, dy, dth = map(float, delta)
        n = len(self.particles)
        cfg = self.config
        dist = np.hypot(dx, dy)
        ex, ey = self.rng.normal(0.0, cfg.translation_noise * dist + 1e-3, (2, n))
        et = self.rng.normal(0.0, cfg.rotation_noise, n)
        th = self.particles[:, 2]
        c, s = np.cos(th), np.sin(th)
        lx, ly = dx + ex, dy + ey
        self.particles[:, 0] += c * lx - s * ly
        self.particles[:, 1] += s * lx + c * ly
        self.particles[:, 2] = wrap_angle(th + dth + et)

    def update(self, rssi_dbm: np.ndarray, sensor=None) -> None:
        """Weigh by one reading (Eq. 12–13, or ``sensor(xy)``: another sensor model's
        log-likelihood at each particle), resample when the effective sample size drops, and
        inject samples from the reading's gridmap likelihood where the average likelihood
        collapsed (kidnapping)."""
        z = normalise_rssi(rssi_dbm)
        if z.sum() <= 0:
            return  # nothing heard: nothing learned
        if sensor is not None:
            log_l = sensor(self.particles[:, :2])
        else:
            mean, var = self._predict(self.particles[:, :2])
            log_l = self._log_likelihood(z, mean, var)
        if self.allowed is not None:
            row, col = self.maps.cells(self.particles[:, :2])
            log_l = np.where(self.allowed[row * self.maps.shape[1] + col], log_l, log_l - 50.0)
        top = float(log_l.max())
        like = np.exp(log_l - top)
        average = float(np.mean(like)) * np.exp(top)
        cfg = self.config
        self._w_slow = average if self._w_slow == 0 else self._w_slow
        self._w_fast = average if self._w_fast == 0 else self._w_fast
        self._w_slow += cfg.slow_rate * (average - self._w_slow)
        self._w_fast += cfg.fast_rate * (average - self._w_fast)
        w = self.weights * like
        total = w.sum()
        self.weights = w / total if total > 0 else np.full(len(w), 1.0 / len(w))
        n = len(self.particles)
        if 1.0 / np.sum(self.weights**2) < cfg.resample_ess * n:
            keep = low_variance_indices(self.weights, n, self.rng)
            self.particles = self.particles[keep]
            self.weights.fill(1.0 / n)
            inject = max(0.0, 1.0 - self._w_fast / self._w_slow) if self._w_slow > 0 else 0.0
            k = int(self.rng.binomial(n, min(inject, 0.5)))
            if k:
                self.particles[:k] = self.sample_from_reading(rssi_dbm, k)

    def _log_likelihood(self, z: np.ndarray, mean: np.ndarray, var: np.ndarray) -> np.ndarray:
        if self.config.sensor == "scan":
            return scan_log_likelihood(z, mean, var, self.config.scan_variance)
        return log_likelihood(z, mean, var)

    def estimate(self) -> tuple[np.ndarray, float]:
        """The weighted mean pose ``(3,)`` and the particles' RMS distance from it (m)."""
        w = self.weights
        xy = w @ self.particles[:, :2]
        th = np.arctan2(w @ np.sin(self.particles[:, 2]), w @ np.cos(self.particles[:, 2]))
        spread = float(np.sqrt(w @ np.sum((self.particles[:, :2] - xy) ** 2, axis=1)))
        return np.array([xy[0], xy[1], th]), spread
