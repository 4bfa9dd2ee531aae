"""Synthetic odometry along a known walk: exact without noise, the stated noise with it, seeded."""

from __future__ import annotations

import numpy as np
import pytest

from sfw_gym.core.errors import ConfigError
from sfw_gym.datasets import synthetic_odometry, walk_poses

SQUARE = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [2.0, 2.0], [0.0, 2.0]])


def test_walk_headings_follow_the_steps_and_hold_when_standing() -> None:
    poses = walk_poses(SQUARE)
    np.testing.assert_allclose(poses[:, 2], [0, 0, np.pi / 2, np.pi / 2, np.pi])
    assert walk_poses(np.zeros((3, 2)))[:, 2].tolist() == [0, 0, 0]
    # standing at first: those scans take the first step's heading
    np.testing.assert_allclose(
        walk_poses(np.array([[0, 0], [0, 0], [0, 1.0]]))[:, 2], [np.pi / 2] * 3
    )


def test_without_noise_odometry_is_the_true_motion() -> None:
    increments, poses = synthetic_odometry(SQUARE, translation_std=0, heading_std_rad=0)
    np.testing.assert_allclose(
        increments, [[2, 0, 0], [0, 2, np.pi / 2], [0, 0, 0], [0, 2, np.pi / 2]], atol=1e-12
    )
    np.testing.assert_allclose(poses[:, :2], SQUARE, atol=1e-12)


def test_noise_is_the_stated_share_of_travel_and_heading_per_step() -> None:
    straight = np.column_stack([np.arange(20001) * 1.5, np.zeros(20001)])
    increments, _ = synthetic_odometry(straight, translation_std=0.05, heading_std_rad=0.02, rng=1)
    assert np.std(increments[:, 0] - 1.5) == pytest.approx(0.05 * 1.5, rel=0.03)
    assert np.std(increments[:, 1]) == pytest.approx(0.05 * 1.5, rel=0.03)
    assert np.std(increments[:, 2]) == pytest.approx(0.02, rel=0.03)


def test_odometry_is_seeded_and_drifts() -> None:
    a = synthetic_odometry(SQUARE, rng=7)[1]
    assert np.array_equal(a, synthetic_odometry(SQUARE, rng=7)[1])
    assert not np.array_equal(a, synthetic_odometry(SQUARE, rng=8)[1])
    assert np.array_equal(a[0], walk_poses(SQUARE)[0])  # starts at the true first pose


def test_bad_noise_or_positions_are_refused() -> None:
    with pytest.raises(ConfigError, match="translation_std must be a finite number >= 0"):
        synthetic_odometry(SQUARE, translation_std=-1)
    with pytest.raises(ConfigError, match="finite positions"):
        walk_poses(np.array([[0.0, np.nan]]))
