"""Tracking a walk with WiFi MCL on one floor's Gaussian gridmaps: global localisation from the
first scan (Alg. 1, no prior), then odometry and scans; with a floorplan the particles live in
its free space and a particle whose move crosses a wall (or ends outside the free space) dies."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import partial

import numpy as np

from sfw_gym.core.errors import ConfigError
from sfw_gym.localization.fingerprinting import FloorMaps
from sfw_gym.localization.mcl import MclConfig, WifiMCL
from sfw_gym.world.floorplan import Floorplan

#: Particles per walk.
TRACK_PARTICLES = 2000
#: The gridmaps' sensor model treats a scan's APs as independent; their errors are not (one
#: body, one device), so the product is overconfident: each AP's scan variance is inflated by
#: this (WiFine val, tracked without a plan: 3.3 m mean error at 1, 2.5 m at 10).
SCAN_VARIANCE_INFLATION = 10.0
#: The share of its weight a particle keeps when its move crosses a wall or ends in one: 0, the
#: plan is the truth; above 0, it may be wrong (WiFine's walks cross its layouts' walls).
WALL_WEIGHT = 0.0
#: Draws of a global initialisation that land in a wall are drawn again at most this often.
_INIT_REDRAWS = 20


@dataclass(frozen=True)
class WalledMCL:
    """A :class:`WifiMCL` whose particles keep to a floorplan's free space."""

    mcl: WifiMCL
    plan: Floorplan | None
    wall_weight: float = WALL_WEIGHT

    def _free(self, xy: np.ndarray) -> np.ndarray:
        return np.ones(len(xy), bool) if self.plan is None else self.plan.is_free(xy)

    def start(self, rssi_dbm: np.ndarray) -> None:
        """Global localisation from one scan (Alg. 1); draws in a wall are drawn again."""
        self.mcl.global_init(rssi_dbm)
        for _ in range(_INIT_REDRAWS):
            stuck = ~self._free(self.mcl.particles[:, :2])
            if not stuck.any():
                break
            self.mcl.particles[stuck] = self.mcl.sample_from_reading(rssi_dbm, int(stuck.sum()))

    def step(self, increment: np.ndarray, rssi_dbm: np.ndarray, sensor=None) -> np.ndarray:
        """Move by an odometry increment, kill what crossed a wall, weigh by the scan (by the
        gridmaps, or ``sensor(xy)``: a log-likelihood per particle); the estimate ``(x, y)``."""
        before = self.mcl.particles[:, :2].copy()
        self.mcl.predict(increment)
        if self.plan is not None:
            after = self.mcl.particles[:, :2]
            dead = ~self.plan.is_free(after) | (self.plan.count_walls(before, after) > 0)
            if dead.all() and self.wall_weight == 0:  # lost: start again from this scan
                self.start(rssi_dbm)
            else:
                w = np.where(dead, self.wall_weight * self.mcl.weights, self.mcl.weights)
                total = w.sum()
                self.mcl.weights = w / total if total > 0 else (~dead) / np.sum(~dead)
        self.mcl.update(rssi_dbm, sensor)
        return self.mcl.estimate()[0][:2]


def tracking_config(floor: FloorMaps, particles: int = TRACK_PARTICLES) -> MclConfig:
    """The filter's settings on ``floor``: the "scan" sensor model with the floor's scan
    variance, inflated by :data:`SCAN_VARIANCE_INFLATION`."""
    return MclConfig(
        particles=particles,
        sensor="scan",
        scan_variance=floor.scan_variance * SCAN_VARIANCE_INFLATION,
    )


def track_walk(
    floor: FloorMaps,
    rssi_dbm: np.ndarray,
    increments: np.ndarray,
    *,
    plan: Floorplan | None = None,
    particles: int = TRACK_PARTICLES,
    wall_weight: float = WALL_WEIGHT,
    config: MclConfig | None = None,
    sensor: Callable[[int, np.ndarray], np.ndarray] | None = None,
    rng: np.random.Generator | int | Sequence[int] | None = 0,
) -> np.ndarray:
    """Estimated positions ``(N, 2)`` along a walk: ``rssi_dbm`` ``(N, L)`` over the training
    access points, ``increments`` ``(N - 1, 3)`` odometry (forward, lateral, turn) between scans;
    ``plan``: walls the particles may not cross (a crossing keeps ``wall_weight`` of a particle's
    weight); ``sensor(k, xy)``: scan k's log-likelihood at positions ``xy`` (default: the
    gridmaps')."""
    rssi = np.asarray(rssi_dbm, np.float64)[:, floor.access_points]
    if np.shape(increments) != (len(rssi) - 1, 3):
        raise ConfigError(
            f"a walk of {len(rssi)} scans needs ({len(rssi) - 1}, 3) odometry increments, "
            f"got {np.shape(increments)}"
        )
    mcl = WifiMCL(
        floor.gridmaps,
        config or tracking_config(floor, particles),
        np.random.default_rng(rng),
        allowed=floor.allowed,
    )
    tracker = WalledMCL(mcl, plan, wall_weight)
    tracker.start(rssi[0])
    estimates = np.empty((len(rssi), 2))
    estimates[0] = mcl.estimate()[0][:2]
    for k, increment in enumerate(increments, start=1):
        scan_sensor = None if sensor is None else partial(sensor, k)
        estimates[k] = tracker.step(increment, rssi[k], scan_sensor)
    return estimates
