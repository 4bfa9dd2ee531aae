"""WaypointWrapper: goal-cell actions driven by the belief-map planner."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import sfw_gym  # noqa: F401
from sfw_gym.core.errors import ConfigError
from sfw_gym.envs.waypoint import WaypointWrapper


@pytest.mark.parametrize("env_id", ["SfW-Explore-v0", "SfW-ExploreDiscrete-v0"])
def test_waypoint_drives_towards_the_goal_and_sums_rewards(env_id):
    env = WaypointWrapper(gym.make(env_id), grid_cells=4, max_steps_per_waypoint=80)
    env.reset(seed=1)
    u = env.unwrapped
    start = np.array(u.scene.robot.pose[:2])
    # the goal cell farthest from the robot
    goals = [env.goal_xy(a) for a in range(env.action_space.n)]
    action = int(np.argmax([np.linalg.norm(g - start) for g in goals]))
    path_before = u.path_length_m
    obs, reward, _, _, info = env.step(action)
    assert isinstance(reward, float)
    assert env.observation_space.contains(obs)
    assert 1 <= info["waypoint_steps"] <= 80
    assert u.path_length_m > path_before
    end = np.array(u.scene.robot.pose[:2])
    assert np.linalg.norm(end - goals[action]) < np.linalg.norm(start - goals[action])


def test_waypoint_rejects_bad_actions_and_args():
    env = WaypointWrapper(gym.make("SfW-ExploreSmall-v0"), grid_cells=3)
    env.reset(seed=0)
    assert env.action_space.n == 9
    for bad in (9, -1, 1.5):
        with pytest.raises(ValueError, match="waypoint action"):
            env.step(bad)
    with pytest.raises(ConfigError, match="grid_cells"):
        WaypointWrapper(gym.make("SfW-ExploreSmall-v0"), grid_cells=0)


def test_waypoint_centres_tile_the_square_around_a_tall_grid():
    from sfw_gym.mapping import GridSpec
    from sfw_gym.navigation import waypoint_goal_xy

    grid = GridSpec((0.0, -5.0), 0.5, (20, 4))  # x in [0, 2], y in [-5, 5]: a 10 m square
    centres = waypoint_goal_xy(grid, 2, np.arange(4))
    np.testing.assert_allclose(centres, [[-1.5, -2.5], [3.5, -2.5], [-1.5, 2.5], [3.5, 2.5]])


def test_block_features_by_hand():
    from sfw_gym.mapping import GridSpec
    from sfw_gym.navigation import BLOCK_FEATURES, block_features

    belief = np.zeros((4, 4), np.uint8)  # rows 2-3: walls
    belief[0:2, 0:2] = 127  # block 0: unknown
    belief[0:2, 2:4] = 255  # block 1: free
    grid = GridSpec((0.0, 0.0), 1.0, (4, 4))
    f = block_features(belief, grid, (0.5, 0.5, 0.0), 2)
    assert BLOCK_FEATURES == ("unknown", "free", "wall", "inside", "distance", "robot")
    np.testing.assert_allclose(f[:, :4], [[1, 0, 0, 1], [0, 1, 0, 1], [0, 0, 1, 1], [0, 0, 1, 1]])
    # distance from (0.5, 0.5) to the block centres (1, 1), (3, 1), (1, 3), (3, 3), over 4 m
    np.testing.assert_allclose(f[:, 4], np.hypot([0.5, 2.5, 0.5, 2.5], [0.5, 0.5, 2.5, 2.5]) / 4)
    np.testing.assert_array_equal(f[:, 5], [1, 0, 0, 0])


def test_driver_backs_off_one_step_after_a_bump_then_ends_the_waypoint():
    from sfw_gym.navigation import WaypointDriver

    env = gym.make("SfW-Explore-v0")
    env.reset(seed=1)
    view = env.unwrapped.robot_view()
    driver = WaypointDriver(grid_cells=4)
    driver.start(view, 15)
    pose = view.odometry_pose
    assert driver.command(pose, bumped=False) is not None
    assert driver.command(pose, bumped=True) == (-1.0, 0.0)  # straight back
    assert driver.command(pose, bumped=False) is None
    assert driver.steps == 2 and not driver.reached and driver.bumps.any()
