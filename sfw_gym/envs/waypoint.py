"""Waypoint actions: the agent picks a goal cell on a coarse grid, a planner drives the robot there.

The planner sees only the robot's belief map and odometry (``robot_view()``), like the classical
agents: believed walls are obstacles, unknown cells are passable at a cost.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from sfw_gym.errors import ConfigError
from sfw_gym.navigation import (
    PurePursuit,
    cells_to_world,
    cost_field,
    free_start,
    to_discrete,
    traversal_costs,
)


class WaypointWrapper(gym.Wrapper):
    """``Discrete(n × n)`` actions: drive to the middle of coarse cell ``a`` (row ``a // n``).

    Each wrapper step plans a path on the belief map to the reachable fine cell nearest the
    coarse cell's centre and follows it (pure pursuit) for at most ``max_steps_per_waypoint``
    env steps, stopping early at the goal, at the episode's end, or after a bump (the planner
    then sees the bump on the map next time). The reward is the sum of the env steps' rewards;
    ``info["waypoint_steps"]`` counts them and ``info["waypoint_reached"]`` says whether the
    goal was reached. A goal no path reaches costs one env step standing still.

    Args:
        env: an SfW-Explore env (continuous or discrete actions).
        grid_cells: n, the coarse grid's side (default 8: 64 goals).
        max_steps_per_waypoint: the most env steps one waypoint may take.
    """

    def __init__(self, env: gym.Env, grid_cells: int = 8, max_steps_per_waypoint: int = 60):
        super().__init__(env)
        if not hasattr(env.unwrapped, "robot_view"):
            raise ConfigError("WaypointWrapper needs an SfW-Explore env (with robot_view())")
        for name, value in (("grid_cells", grid_cells), ("max_steps_per_waypoint",
                                                          max_steps_per_waypoint)):  # fmt: skip
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise ConfigError(f"{name} must be a positive integer, got {value!r}")
        self.grid_cells = grid_cells
        self.max_steps_per_waypoint = max_steps_per_waypoint
        self.action_space = spaces.Discrete(grid_cells * grid_cells)
        self._follower = PurePursuit()

    def goal_xy(self, action: int) -> np.ndarray:
        """World (x, y) of the centre of coarse cell ``action``."""
        grid = self.env.unwrapped.robot_view()["grid"]
        x0, y0, x1, y1 = grid.bounds
        row, col = divmod(int(action), self.grid_cells)
        return np.array([x0 + (col + 0.5) * (x1 - x0) / self.grid_cells,
                         y0 + (row + 0.5) * (y1 - y0) / self.grid_cells])  # fmt: skip

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        """Plan to waypoint ``action`` and drive there (see the class doc)."""
        a = np.asarray(action)
        if a.shape != () or a.dtype.kind not in "iu" or not 0 <= int(a) < self.action_space.n:
            raise ValueError(
                f"waypoint action must be an integer in [0, {self.action_space.n}), got {action!r}"
            )
        path, pose = self._plan(self.goal_xy(int(a)))
        self._follower.set_path(path)
        discrete = self.env.unwrapped.action_type == "discrete"
        total, steps, collisions = 0.0, 0, self.env.unwrapped.collisions
        while True:
            linear, angular = self._follower.command(pose)
            if not self._follower.has_path and steps > 0:
                break
            command = (
                to_discrete(linear, angular)
                if discrete
                else np.array([linear, angular], np.float32)
            )
            obs, reward, terminated, truncated, info = self.env.step(command)
            total += float(reward)
            steps += 1
            pose = tuple(info["odometry_pose"])
            bumped = info["collisions"] > collisions
            collisions = info["collisions"]
            if terminated or truncated or bumped or steps >= self.max_steps_per_waypoint:
                break
        reached = len(path) > 0 and not self._follower.has_path
        info = dict(info, waypoint_steps=steps, waypoint_reached=reached)
        return obs, total, terminated, truncated, info

    def _plan(self, goal_xy: np.ndarray) -> tuple[np.ndarray, tuple[float, float, float]]:
        """A world path to the reachable cell nearest ``goal_xy`` and the current odometry pose."""
        view = self.env.unwrapped.robot_view()
        pose = view["odometry_pose"]
        grid = view["grid"]
        cost = traversal_costs(view["belief_u8"], grid.resolution_m, view["radius_m"])
        start = tuple(int(v) for v in grid.world_to_cell(np.array(pose[:2])))
        field = cost_field(free_start(cost, start), start, grid.resolution_m)
        reachable = field.reachable()
        if not reachable.any():
            return np.zeros((0, 2)), pose
        rows, cols = np.nonzero(reachable)
        goal_rc = grid.world_to_cell(goal_xy)
        nearest = np.argmin((rows - goal_rc[0]) ** 2 + (cols - goal_rc[1]) ** 2)
        cells = field.path((int(rows[nearest]), int(cols[nearest])))
        return cells_to_world(grid, cells), pose
