"""Synthetic odometry along a walk whose true positions are known: the robot's odometry model
(the true motion in the walker's frame plus Gaussian noise, ``translation_std`` per metre and
``heading_std_rad`` per step; the drift env's 5 % and 0.02 rad by default), seeded."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from sfw_gym.core.angles import wrap_angle
from sfw_gym.core.errors import ConfigError

#: The drift envs' odometry noise (sfw_gym.envs: SfW-Explore-Drift-v0 and kin).
DRIFT_TRANSLATION_STD = 0.05
DRIFT_HEADING_STD_RAD = 0.02


def walk_poses(positions: np.ndarray) -> np.ndarray:
    """``(N, 3)`` true poses of a walk through ``positions`` ``(N, 2)``: each heading the
    direction of the step that arrived there (the first: of the first step; 0 for a walk that
    never moves); a scan taken standing still keeps the heading before it."""
    xy = np.asarray(positions, np.float64)
    if xy.ndim != 2 or xy.shape[1] != 2 or not np.isfinite(xy).all():
        raise ConfigError(f"a walk needs finite positions (N, 2), got shape {xy.shape}")
    step = np.diff(xy, axis=0)
    moved = np.hypot(step[:, 0], step[:, 1]) > 1e-9
    heading = np.zeros(len(xy))
    if moved.any():
        # each pose takes the last step that moved up to it (the first such step before any)
        last_moved = np.maximum.accumulate(np.where(moved, np.arange(len(moved)), -1))
        last_moved[last_moved < 0] = np.argmax(moved)
        angles = np.arctan2(step[:, 1], step[:, 0])
        heading[0] = angles[np.argmax(moved)]
        heading[1:] = angles[last_moved]
    return np.column_stack([xy, heading])


def synthetic_odometry(
    positions: np.ndarray,
    *,
    translation_std: float = DRIFT_TRANSLATION_STD,
    heading_std_rad: float = DRIFT_HEADING_STD_RAD,
    rng: np.random.Generator | int | Sequence[int] | None = 0,
) -> tuple[np.ndarray, np.ndarray]:
    """Odometry along a walk: ``(increments (N-1, 3), poses (N, 3))``. Each increment is the
    true motion between consecutive :func:`walk_poses` in the frame of the first (forward,
    lateral, turn), plus N(0, ``translation_std`` × distance) on forward and lateral and
    N(0, ``heading_std_rad``) on the turn; the poses integrate them from the true first pose."""
    for name, value in (("translation_std", translation_std), ("heading_std_rad", heading_std_rad)):
        if not (np.isfinite(value) and value >= 0):
            raise ConfigError(f"{name} must be a finite number >= 0, got {value!r}")
    rng = np.random.default_rng(rng)
    true = walk_poses(positions)
    d = np.diff(true[:, :2], axis=0)
    c, s = np.cos(true[:-1, 2]), np.sin(true[:-1, 2])
    forward = c * d[:, 0] + s * d[:, 1]
    lateral = -s * d[:, 0] + c * d[:, 1]
    turn = wrap_angle(np.diff(true[:, 2]))
    noise = rng.standard_normal((len(d), 3))
    distance = np.hypot(d[:, 0], d[:, 1])
    forward = forward + translation_std * distance * noise[:, 0]
    lateral = lateral + translation_std * distance * noise[:, 1]
    turn = turn + heading_std_rad * noise[:, 2]
    increments = np.column_stack([forward, lateral, turn])
    poses = np.empty_like(true)
    poses[0] = true[0]
    for k, (f, lat, dth) in enumerate(increments):
        x, y, th = poses[k]
        poses[k + 1] = (
            x + np.cos(th) * f - np.sin(th) * lat,
            y + np.sin(th) * f + np.cos(th) * lat,
            th + dth,
        )
    poses[:, 2] = wrap_angle(poses[:, 2])
    return increments, poses
