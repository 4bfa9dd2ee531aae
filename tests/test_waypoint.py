"""WaypointWrapper: goal-cell actions driven by the belief-map planner."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import sfw_gym  # noqa: F401
from sfw_gym.envs.waypoint import WaypointWrapper
from sfw_gym.errors import ConfigError


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
