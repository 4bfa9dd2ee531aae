"""Waypoint actions: the agent picks a goal cell on a coarse grid, a planner drives the robot there
(:mod:`sfw_gym.navigation.waypoints`).
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from sfw_gym.core.errors import ConfigError
from sfw_gym.envs.explore import unwrap_sfw
from sfw_gym.navigation.planning import to_discrete
from sfw_gym.navigation.waypoints import (
    BLOCK_FEATURES,
    WaypointDriver,
    block_features,
    waypoint_goal_xy,
)


class WaypointWrapper(gym.Wrapper):
    """``Discrete(n × n)`` actions: drive to the middle of coarse cell ``a`` (row ``a // n``).

    The coarse cells tile the observation's ``map`` image (see :func:`waypoint_goal_xy`). Each
    wrapper step plans a path on the belief map to the reachable fine cell nearest the coarse
    cell's centre and drives it with a :class:`WaypointDriver`, until the goal, the step cap, a
    bump, or the episode's end. The reward is the sum of the env steps'
    rewards; ``info["waypoint_steps"]`` counts them and ``info["waypoint_reached"]`` says
    whether the goal was reached. The observation gains ``blocks``: what the robot knows of each
    block (:func:`block_features`), so that a policy can score the blocks one by one.

    Args:
        env: an SfW-Explore env (continuous or discrete actions).
        grid_cells: n, the coarse grid's side (default 8: 64 goals).
        max_steps_per_waypoint: the most env steps one waypoint may take.
    """

    def __init__(
        self,
        env: gym.Env,
        grid_cells: int = 8,
        max_steps_per_waypoint: int = 60,
    ):
        super().__init__(env)
        try:
            self._robot_view = unwrap_sfw(env).robot_view
        except ConfigError:
            raise ConfigError(
                "WaypointWrapper needs an SfW-Explore env (with robot_view())"
            ) from None
        assert isinstance(env.observation_space, spaces.Dict)
        self.driver = WaypointDriver(grid_cells, max_steps_per_waypoint)
        self._collisions = 0
        self.n_waypoints = grid_cells * grid_cells
        self.action_space = spaces.Discrete(self.n_waypoints)
        blocks = spaces.Box(0.0, 2.0, (grid_cells * grid_cells, len(BLOCK_FEATURES)), np.float32)
        self.observation_space = spaces.Dict({**env.observation_space.spaces, "blocks": blocks})

    def reset(self, **kwargs: Any) -> tuple[Any, dict[str, Any]]:
        """Reset the env and the driver's bump memory."""
        self.driver.reset()
        obs, info = self.env.reset(**kwargs)
        self._collisions = info["collisions"]
        return self._with_blocks(obs), info

    def goal_xy(self, action: int) -> np.ndarray:
        """World (x, y) of the centre of coarse cell ``action``."""
        grid = self._robot_view().grid
        return waypoint_goal_xy(grid, self.driver.grid_cells, action)

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        """Plan to waypoint ``action`` and drive there (see the class doc)."""
        a = np.asarray(action)
        if a.shape != () or a.dtype.kind not in "iu" or not 0 <= int(a) < self.n_waypoints:
            raise ConfigError(
                f"waypoint action must be an integer in [0, {self.n_waypoints}), got {action!r}"
            )
        view = self._robot_view()
        self.driver.start(view, int(a))
        pose, bumped = view.odometry_pose, False
        total, collisions = 0.0, self._collisions
        while (command := self.driver.command(pose, bumped)) is not None:
            action_ = (
                to_discrete(*command)
                if view.action_type == "discrete"
                else np.array(command, np.float32)
            )
            obs, reward, terminated, truncated, info = self.env.step(action_)
            total += float(reward)
            pose = tuple(info["odometry_pose"])
            bumped, collisions = info["collisions"] > collisions, info["collisions"]
            if terminated or truncated:
                break
        self._collisions = collisions
        info = dict(info, waypoint_steps=self.driver.steps, waypoint_reached=self.driver.reached)
        return self._with_blocks(obs), total, terminated, truncated, info

    def _with_blocks(self, obs: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        view = self._robot_view()
        blocks = block_features(
            view.belief_u8, view.grid, view.odometry_pose, self.driver.grid_cells
        )
        return {**obs, "blocks": blocks}
