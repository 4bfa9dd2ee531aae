"""Radio+LiDAR SLAM and the LiDAR-only baseline (sfw_gym.slam.radio_lidar) on recorded drives,
and SfW-ExploreLidar-v0, which maps along it as the robot drives."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

from sfw_gym.agents import FrontierAgent
from sfw_gym.core.errors import ConfigError
from sfw_gym.evaluation.drives import record_frontier_drive
from sfw_gym.slam import (
    LidarSlamConfig,
    OnlineRadioLidarSlam,
    RadioSlamConfig,
    absolute_trajectory_error,
    lidar_slam,
    radio_slam,
)

DRIFT = {"odometry_translation_std": 0.05, "odometry_heading_std_rad": 0.02}


@pytest.fixture(scope="module")
def drive():
    """A 900-step frontier drive with drift, 16 background APs and the LiDAR (seed 7)."""
    return record_frontier_drive(
        "SfW-Explore-v0", 7, 900, robot=DRIFT, n_background_aps=16, lidar={}
    )


def ate(poses, drive):
    return absolute_trajectory_error(poses, drive["truth"], align=False)


@pytest.mark.episode
def test_lidar_only_slam_removes_most_of_the_odometrys_drift(drive):
    result = lidar_slam(drive["odometry"], drive["keyframe_scans"], radio=drive["slam_config"])
    assert result.consecutive_registered > 0.8  # walls in view nearly everywhere indoors
    assert ate(result.poses, drive) < 0.3 * ate(drive["odometry"], drive)


@pytest.mark.episode
def test_radio_lidar_slam_beats_radio_slam_and_closes_lidar_loops(drive):
    radio = ate(
        radio_slam(drive["odometry"], drive["fingerprints"], drive["slam_config"]).poses, drive
    )
    both = lidar_slam(
        drive["odometry"],
        drive["keyframe_scans"],
        drive["fingerprints"],
        radio=drive["slam_config"],
    )
    assert len(both.lidar_closures) > 0
    # every accepted LiDAR closure joins poses that are truly close
    ends = drive["truth"][both.lidar_closures]
    assert (
        np.hypot(*(ends[:, 0, :2] - ends[:, 1, :2]).T).max()
        < LidarSlamConfig().closure_radius_m + 1.0
    )
    assert ate(both.poses, drive) < 0.5 * radio


@pytest.mark.episode
def test_without_scan_matching_the_pipeline_is_no_better_than_its_first_stage(drive):
    """Flip side of the tests above: with ICP never accepting (fitness bound ~0) nothing of the
    LiDAR stage is used and Radio+LiDAR returns Radio SLAM's trajectory."""
    from sfw_gym.slam import IcpConfig

    never = IcpConfig(max_fitness=1e-12)
    both = lidar_slam(
        drive["odometry"],
        drive["keyframe_scans"],
        drive["fingerprints"],
        radio=drive["slam_config"],
        icp_config=never,
    )
    radio = radio_slam(drive["odometry"], drive["fingerprints"], drive["slam_config"]).poses
    assert both.consecutive_registered == 0 and len(both.lidar_closures) == 0
    assert ate(both.poses, drive) == pytest.approx(ate(radio, drive), abs=0.05)


@pytest.mark.episode
def test_a_missing_keyframe_scan_is_one_clear_error(drive):
    scans = dict(drive["keyframe_scans"])
    del scans[5]
    with pytest.raises(ConfigError, match=r"no scan for keyframe pose\(s\) \[5\]"):
        lidar_slam(drive["odometry"], scans, radio=drive["slam_config"])


def test_the_online_solver_keeps_scans_only_at_keyframes_and_the_latest_pose():
    slam = OnlineRadioLidarSlam(RadioSlamConfig(keyframe_every=5, solve_every=1000))
    points = np.array([[1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
    for k in range(23):
        slam.add((0.1 * k, 0.0, 0.0), np.full(4, -50.0), points + k)
    assert sorted(slam._scans) == [0, 5, 10, 15, 20, 22]
    np.testing.assert_array_equal(slam._scans[22], points + 22)
    with pytest.raises(ConfigError, match="needs each pose's LiDAR scan"):
        slam.add((0.0, 0.0, 0.0), np.full(4, -50.0))


@pytest.mark.episode
def test_the_lidar_env_maps_along_a_trajectory_far_better_than_its_odometry():
    env = gym.make("SfW-ExploreLidar-v0", max_steps=400)
    drift = gym.make("SfW-ExploreDrift-v0", max_steps=400)
    errors = []
    for e in (env, drift):
        obs, info = e.reset(seed=5)
        agent = FrontierAgent()
        agent.reset(e, seed=5)
        done = False
        while not done:
            obs, _, terminated, truncated, info = e.step(agent.act(obs))
            done = terminated or truncated
        errors.append(info["ate_m"])
    assert obs is not None and "lidar" in env.observation_space.spaces
    assert errors[0] < 0.5 * errors[1], errors


@pytest.mark.parametrize(("observability", "follows"), [(0.03, "odometry"), (0.3, "icp")])
def test_a_weakly_constrained_registration_far_from_the_odometry_is_not_used(
    monkeypatch, observability, follows
):
    """ICP sliding 0.5 m along a corridor (low observability) loses to the odometry; the same
    correction from a well-constrained pair is taken."""
    from sfw_gym.slam import radio_lidar
    from sfw_gym.slam.scan_matching import IcpResult

    def slid(points_a, points_b, initial, config):
        delta = np.asarray(initial, np.float64) + np.array([0.5, 0.0, 0.0])
        return IcpResult(delta, 0.001, 100, 5, True, observability)

    monkeypatch.setattr(radio_lidar, "icp", slid)
    odometry = np.column_stack([np.arange(11) * 0.1, np.zeros(11), np.zeros(11)])
    scans = {k: np.ones((100, 2)) for k in (0, 5, 10)}
    poses = lidar_slam(odometry, scans, radio=RadioSlamConfig(keyframe_every=5)).poses
    expected = 1.0 if follows == "odometry" else 2.0  # two keyframe steps of 0.5 + 0.5
    assert poses[-1, 0] == pytest.approx(expected, abs=1e-6)


@pytest.mark.episode
def test_the_recorded_keyframe_scans_lie_on_the_walls_seen_from_their_true_poses(drive):
    import shapely

    walls = drive["env"].scene.floorplan.free_space.boundary
    for k in list(drive["keyframe_scans"])[::40]:
        x, y, theta = drive["truth"][k]
        points = drive["keyframe_scans"][k]
        c, s = np.cos(theta), np.sin(theta)
        world = points @ np.array([[c, s], [-s, c]]) + [x, y]
        off = shapely.distance(shapely.points(world), walls)
        assert len(points) > 100 and np.quantile(off, 0.99) < 0.05, (k, off.max())
