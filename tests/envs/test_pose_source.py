"""Where the env maps from: odometry (the default), Radio SLAM (the map rebuilt along each
correction), or the true pose."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import sfw_gym  # noqa: F401  (registration)
from sfw_gym.agents import FrontierAgent
from sfw_gym.core.errors import ConfigError
from sfw_gym.mapping import SparseInverseKVisibility
from sfw_gym.slam import absolute_trajectory_error

DRIFT = {"odometry_translation_std": 0.05, "odometry_heading_std_rad": 0.02}


def run(pose_source: str, steps: int = 600, seed: int = 2_000_005, **kwargs):
    env = gym.make(
        "SfW-Explore-v0",
        robot=DRIFT,
        n_background_aps=16,
        pose_source=pose_source,
        max_steps=steps,
        **kwargs,
    )
    obs, info = env.reset(seed=seed)
    agent = FrontierAgent()
    agent.reset(env, seed=seed)
    done = False
    while not done:
        obs, _, terminated, truncated, info = env.step(agent.act(obs))
        done = terminated or truncated
    return env.unwrapped, info


def test_radio_slam_rebuilds_the_map_exactly_along_its_corrected_trajectory():
    env, info = run("radio_slam", slam={"solve_every": 50})
    assert env.slam.n_solves == 12
    estimates = env.pose_estimates.view
    assert np.abs(estimates[:, :2] - env.slam.odometry[:, :2]).max() > 0.2  # it corrected
    # the live map equals one built from scratch along the final estimate...
    mapper = SparseInverseKVisibility(env.grid, env.scene.radio.routers, env.config.mapper)
    x0, y0, x1, y1 = env.grid.bounds
    for (x, y, theta), rssi, bump in zip(
        estimates, env.rssi_history.view, env.map_history.bumps, strict=True
    ):
        if x0 <= x < x1 and y0 <= y < y1:
            mapper.update((x, y), rssi.astype(np.float64), bump, theta)
    np.testing.assert_array_equal(env.mapper.occupancy_u8, mapper.occupancy_u8)
    # ...and so do the metrics tracked on the way, and the trajectory error
    from sfw_gym.mapping import metrics

    assert info["free_iou"] == pytest.approx(
        metrics.free_iou(mapper.occupancy_u8, env.scene.truth_u8)
    )
    truth = np.asarray(env.trajectory)
    assert info["ate_m"] == pytest.approx(
        absolute_trajectory_error(estimates, truth, align=False), rel=1e-9
    )
    assert info["pose_error_m"] == pytest.approx(np.hypot(*(estimates[-1, :2] - truth[-1])))
    np.testing.assert_array_equal(env.odometry_trajectory.view, estimates[:, :2])


@pytest.mark.slow
def test_radio_slam_corrects_the_drift_that_odometry_leaves():
    seeds = (2_000_005, 2_000_006, 2_000_007)
    odometry = np.mean([run("odometry", steps=1500, seed=s)[1]["ate_m"] for s in seeds])
    slam = np.mean([run("radio_slam", steps=1500, seed=s)[1]["ate_m"] for s in seeds])
    assert odometry > 2.0  # measured 2.9 m
    assert slam < 0.6 * odometry  # measured 0.9 m


def test_the_true_pose_maps_without_error_and_odometry_reports_its_drift():
    _, true = run("true", steps=200)
    assert true["ate_m"] == 0.0 and true["pose_error_m"] == 0.0
    np.testing.assert_array_equal(true["pose_estimate"], true["true_pose"])
    _, odometry = run("odometry", steps=200)
    np.testing.assert_array_equal(odometry["pose_estimate"], odometry["odometry_pose"])
    assert odometry["ate_m"] > 0.0


def test_radio_slam_without_access_points_is_refused_by_name():
    with pytest.raises(ConfigError, match=r"pose_source='radio_slam'.*n_background_aps"):
        gym.make("SfW-Explore-v0", pose_source="radio_slam")
    with pytest.raises(ConfigError, match="pose_source"):
        gym.make("SfW-Explore-v0", pose_source="gps")
    with pytest.raises(ConfigError, match="slam"):
        gym.make("SfW-ExploreRadioSLAM-v0", slam={"keyframes": 3})


def test_radio_slam_weighs_odometry_by_the_robots_noise_unless_told_otherwise():
    env = gym.make("SfW-ExploreRadioSLAM-v0").unwrapped
    # 5 % of a full-speed step (0.5 m/s x 0.2 s), 0.02 rad per step
    assert env.config.slam.odometry_sigma_m == pytest.approx(0.005)
    assert env.config.slam.odometry_sigma_rad == pytest.approx(0.02)
    own = gym.make("SfW-ExploreRadioSLAM-v0", slam={"odometry_sigma_m": 0.03}).unwrapped
    assert own.config.slam.odometry_sigma_m == 0.03


def test_radio_lidar_slam_needs_the_lidar_and_access_points_by_name():
    with pytest.raises(ConfigError, match=r"pose_source='radio_lidar'.*lidar=\{\}"):
        gym.make("SfW-Explore-v0", pose_source="radio_lidar", n_background_aps=4)
    with pytest.raises(ConfigError, match=r"pose_source='radio_lidar'.*n_background_aps"):
        gym.make("SfW-Explore-v0", pose_source="radio_lidar", lidar={})
    with pytest.raises(ConfigError, match=r"lidar\.max_range_m"):
        gym.make("SfW-Explore-v0", lidar={"max_range_m": -1})


def test_the_lidar_observation_is_each_range_over_the_max_and_one_for_no_return():
    env = gym.make("SfW-Explore-v0", lidar={"max_range_m": 2.0, "beams": 90})
    obs, info = env.reset(seed=4)
    ranges = info["lidar_ranges"]
    assert obs["lidar"].shape == (90,) and env.observation_space.contains(obs)
    assert np.isinf(ranges).any() and np.isfinite(ranges).any()  # some walls within 2 m
    expected = np.where(np.isinf(ranges), 1.0, np.minimum(ranges / 2.0, 1.0))  # noise: ≤ 1
    np.testing.assert_allclose(obs["lidar"], expected, rtol=1e-6)
