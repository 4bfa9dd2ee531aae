"""Radio SLAM on real walks: a walk's real fingerprints (WiFine's, say) over synthetic odometry
made from its true positions, scored against them.

:func:`slam_on_walk` makes the odometry (:func:`sfw_gym.datasets.odometry.synthetic_odometry`, the
robot's noise model at a stated level, seeded), runs :func:`radio_slam` on it and the walk's
fingerprints with settings for scans taken metres apart (:func:`real_walk_config`), and returns
both trajectories' ATE and the closures it kept, each judged against the true distance between
its two scans (:func:`wrong_closures`).
"""

from __future__ import annotations

import math
import zlib
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np

from sfw_gym.core.angles import wrap_angle
from sfw_gym.core.errors import ConfigError
from sfw_gym.datasets.fingerprints import Fingerprints
from sfw_gym.datasets.odometry import (
    DRIFT_HEADING_STD_RAD,
    DRIFT_TRANSLATION_STD,
    synthetic_odometry,
    walk_poses,
)
from sfw_gym.slam.metrics import absolute_trajectory_error
from sfw_gym.slam.radio_slam import RadioSlamConfig, lateral_offsets, radio_slam

#: A closure is wrong when its distance estimate misses the true one by more than this many of
#: its own standard deviations …
WRONG_SIGMAS = 3.0
#: … or by more than this many metres, whichever is smaller.
WRONG_ERROR_M = 3.0

#: A heading closure is wrong when the turn it asks for misses the true one (between the two
#: scans' directions of motion) by more than this: it picked the wrong multiple of 90°.
WRONG_TURN_RAD = math.pi / 4

#: Radio SLAM's settings for scans a few seconds (~1.7 m) apart, chosen on WiFine train walks
#: (docs/results/slam.md, "Radio SLAM on real WiFine scans"); the odometry's sigmas come from the
#: noise level (:func:`real_walk_config`).
REAL_WALK_SETTINGS: dict[str, Any] = {
    "keyframe_every": 1,  # a scan every ~1.7 m: every one a node (~160 a walk)
    "min_rssi_dbm": -75.0,  # the weak readings (-76 … -83 dBm) flicker and go stale
    "sigma_db": 6.0,
    "train_travel_m": 6.0,  # the model's pairs: up to ~3 scans apart …
    "train_lag": 6,
    "min_travel_m": 20.0,  # closures: 20 m of walking apart, as the revisits
    "threshold": 0.4,
    "radius_db_per_ap": 4.0,
    "min_sigma_m": 0.5,
    "outlier_sigma": 2.0,
    # corridor closures: a closure's two scans walked the same or opposite way (within 40°)
    # lie each on the other's line of travel, ± 1.5 m, the kernel at 2 sigmas (heading closures,
    # heading_snap_deg, were tried and are off: docs/results/history.md says why)
    "corridor_sigma_m": 1.5,
    "corridor_max_turn_rad": 0.7,
    "corridor_robust_scale": 2.0,
}


def real_walk_config(
    translation_std: float = DRIFT_TRANSLATION_STD,
    heading_std_rad: float = DRIFT_HEADING_STD_RAD,
    **overrides: Any,
) -> RadioSlamConfig:
    """:data:`REAL_WALK_SETTINGS` with the graph's odometry sigmas matched to the synthetic
    odometry's noise: ``translation_std`` per metre of each step, ``heading_std_rad`` per step
    (a 1 cm floor per step, so that a scan taken standing still is not a rigid edge);
    ``overrides``: any other :class:`RadioSlamConfig` field."""
    settings = REAL_WALK_SETTINGS | {
        "odometry_sigma_m": 0.01,
        "odometry_sigma_per_m": max(translation_std, 1e-4),
        "odometry_sigma_rad": max(heading_std_rad, 1e-4),
    }
    return RadioSlamConfig(**(settings | overrides))


def wrong_closures(
    true_m: np.ndarray,
    distance_m: np.ndarray,
    sigma_m: np.ndarray,
    *,
    n_sigma: float = WRONG_SIGMAS,
    max_error_m: float = WRONG_ERROR_M,
) -> np.ndarray:
    """Which closures are wrong: the true distance between their scans ``true_m`` differs from
    their estimate ``distance_m`` by more than ``n_sigma`` of their standard deviation
    ``sigma_m``, or by more than ``max_error_m`` metres (a closure must be both within its own
    stated uncertainty and within ``max_error_m`` to count as right)."""
    error = np.abs(np.asarray(true_m, np.float64) - np.asarray(distance_m, np.float64))
    return (error > n_sigma * np.asarray(sigma_m, np.float64)) | (error > max_error_m)


@dataclass
class WalkSlamResult:
    """One walk: its scans, length, the ATE (m, aligned) of the odometry and of Radio SLAM, and
    the closures Radio SLAM kept ``(C, 2)`` (scan indices) with their distance estimates, standard
    deviations, the true distances and which are wrong (:func:`wrong_closures`)."""

    label: str
    n_scans: int
    length_m: float
    ate_odometry_m: float
    ate_slam_m: float
    # RadioSlamResult's closure fields (as float64), each with its truth beside it: the same
    # names so that a walk's result reads as the SLAM result it scores
    closures: np.ndarray
    closure_distance_m: np.ndarray
    closure_sigma_m: np.ndarray
    closure_true_m: np.ndarray
    wrong: np.ndarray
    # heading closures: the turn each closure asked for (NaN: none), the true turn between its
    # scans' directions of motion, and which asked for the wrong one (WRONG_TURN_RAD)
    closure_turn_rad: np.ndarray | None = None
    closure_true_turn_rad: np.ndarray | None = None
    wrong_turn: np.ndarray | None = None
    # corridor closures: which closures kept one (None: off), the true lateral offset between
    # their scans (the larger of each off the other's true line of travel, m), which are wrong
    # (off the line by more than 3 of their sigmas or 3 m, as wrong_closures)
    corridor: np.ndarray | None = None
    corridor_true_m: np.ndarray | None = None
    wrong_corridor: np.ndarray | None = None

    @property
    def n_corridor(self) -> int:
        return 0 if self.corridor is None else int(self.corridor.sum())

    @property
    def n_wrong_corridor(self) -> int:
        return 0 if self.wrong_corridor is None else int(self.wrong_corridor.sum())

    @property
    def n_turns(self) -> int:
        return 0 if self.closure_turn_rad is None else int(np.isfinite(self.closure_turn_rad).sum())

    @property
    def n_wrong_turns(self) -> int:
        return 0 if self.wrong_turn is None else int(self.wrong_turn.sum())

    @property
    def n_closures(self) -> int:
        return len(self.closures)

    @property
    def n_wrong(self) -> int:
        return int(self.wrong.sum())


def slam_on_walk(
    positions: np.ndarray,
    rssi_dbm: np.ndarray,
    *,
    translation_std: float = DRIFT_TRANSLATION_STD,
    heading_std_rad: float = DRIFT_HEADING_STD_RAD,
    seed: int | np.random.Generator | None = 0,
    config: RadioSlamConfig | None = None,
    label: str = "walk",
) -> WalkSlamResult:
    """Radio SLAM on one walk: true ``positions`` ``(N, 2)`` in scan order and their readings
    ``rssi_dbm`` ``(N, L)`` (NaN where not heard, as :class:`Fingerprints` keeps them; Radio
    SLAM's similarity counts only the APs heard). The odometry is synthetic at the stated noise
    (seeded); ``config`` defaults to :func:`real_walk_config` at that noise."""
    xy = np.asarray(positions, np.float64)
    rssi = np.asarray(rssi_dbm, np.float64)
    if rssi.ndim != 2 or len(rssi) != len(xy):
        raise ConfigError(f"{label}: readings {rssi.shape} do not match positions {xy.shape}")
    if len(xy) < 3:
        raise ConfigError(f"{label}: a walk needs at least 3 scans, got {len(xy)}")
    cfg = config or real_walk_config(translation_std, heading_std_rad)
    _, odometry = synthetic_odometry(
        xy, translation_std=translation_std, heading_std_rad=heading_std_rad, rng=seed
    )
    result = radio_slam(odometry, rssi, cfg)
    pairs = np.asarray(result.closures, np.int64).reshape(-1, 2)
    true_m = np.linalg.norm(xy[pairs[:, 1]] - xy[pairs[:, 0]], axis=1)
    heading = walk_poses(xy)[:, 2]  # the true directions of motion: to judge, not to solve
    true_turn = wrap_angle(heading[pairs[:, 1]] - heading[pairs[:, 0]])
    turn = result.closure_turn_rad
    if turn is None:
        turn = np.full(len(pairs), np.nan)
    wrong_turn = np.isfinite(turn) & (
        np.abs(wrap_angle(true_turn - np.nan_to_num(turn))) > WRONG_TURN_RAD
    )
    true_poses = walk_poses(xy)
    a, b = true_poses[pairs[:, 0]], true_poses[pairs[:, 1]]
    corridor_true = np.maximum(lateral_offsets(a, b), lateral_offsets(b, a))
    corridor = result.closure_corridor
    wrong_corridor = None
    if corridor is not None:
        wrong_corridor = corridor & wrong_closures(
            corridor_true, np.zeros(len(pairs)), np.full(len(pairs), cfg.corridor_sigma_m)
        )
    return WalkSlamResult(
        label=label,
        n_scans=len(xy),
        length_m=float(np.linalg.norm(np.diff(xy, axis=0), axis=1).sum()),
        ate_odometry_m=absolute_trajectory_error(odometry, xy),
        ate_slam_m=absolute_trajectory_error(result.poses, xy),
        closures=pairs,
        closure_distance_m=np.asarray(result.closure_distance_m, np.float64),
        closure_sigma_m=np.asarray(result.closure_sigma_m, np.float64),
        closure_true_m=true_m,
        wrong=wrong_closures(true_m, result.closure_distance_m, result.closure_sigma_m),
        closure_turn_rad=turn,
        closure_true_turn_rad=true_turn,
        wrong_turn=wrong_turn,
        corridor=corridor,
        corridor_true_m=corridor_true,
        wrong_corridor=wrong_corridor,
    )


def walk_seed(seed: int, label: str) -> np.random.Generator:
    """The odometry noise of walk ``label`` under ``seed``: the same whichever walks run with
    it and in whatever order."""
    return np.random.default_rng([seed, zlib.crc32(label.encode())])


def slam_on_walks(
    fingerprints: Fingerprints,
    *,
    translation_std: float = DRIFT_TRANSLATION_STD,
    heading_std_rad: float = DRIFT_HEADING_STD_RAD,
    seed: int = 0,
    config: RadioSlamConfig | None = None,
    labels: Iterable[str] | None = None,
) -> Iterator[WalkSlamResult]:
    """:func:`slam_on_walk` on each walk of ``fingerprints`` (:meth:`Fingerprints.walks`: one
    trajectory on one floor, in time order), or on those named in ``labels``; each walk's
    odometry seeded by :func:`walk_seed`."""
    wanted = None if labels is None else set(labels)
    for label, rows in fingerprints.walks():
        if wanted is not None and label not in wanted:
            continue
        walk = fingerprints.subset(rows)
        yield slam_on_walk(
            walk.positions,
            walk.rssi_dbm,
            translation_std=translation_std,
            heading_std_rad=heading_std_rad,
            seed=walk_seed(seed, label),
            config=config,
            label=label,
        )


__all__ = [
    "REAL_WALK_SETTINGS",
    "WRONG_ERROR_M",
    "WRONG_SIGMAS",
    "WRONG_TURN_RAD",
    "WalkSlamResult",
    "real_walk_config",
    "slam_on_walk",
    "slam_on_walks",
    "walk_seed",
    "wrong_closures",
]
