"""Driving to waypoints on the belief map: the coarse waypoint grid, path planning, the driver.

The planner sees only the robot's belief map and odometry (``robot_view()``), like the classical
agents: believed walls are obstacles, unknown cells are passable at a cost. Shared by the
waypoint wrapper (training) and the learned agent (evaluation), so both drive alike.
"""

from __future__ import annotations

import numpy as np

from sfw_gym.core.config import check
from sfw_gym.mapping.grid import GridSpec
from sfw_gym.navigation.planning import (
    PurePursuit,
    belief_classes,
    cells_to_world,
    cost_field,
    free_start,
    mark_contact,
    to_discrete,
    traversal_costs,
)
from sfw_gym.navigation.view import RobotView


class WaypointDriver:
    """Drives to one waypoint at a time: plans on the belief map, follows the path (pure pursuit).

    A waypoint ends when its goal is reached, after ``max_steps_per_waypoint`` env steps, or at
    a bump while driving forward: the driver remembers the contact region ahead of the robot as
    an obstacle for its later plans (the mapper marks one cell; walls are longer) and, with
    continuous actions, reverses one step first, so the next waypoint starts clear of the wall.
    With discrete actions, contact while turning in place (the robot still touching the wall it
    bumped) does not end the waypoint: the robot turns away and drives on. A goal no path
    reaches costs one step standing still. Shared by :class:`WaypointWrapper` (training) and
    :class:`sfw_gym.agents.WaypointPPOAgent` (evaluation), so both drive alike.
    """

    def __init__(self, grid_cells: int = 8, max_steps_per_waypoint: int = 60) -> None:
        self.grid_cells = check("grid_cells", grid_cells, integer=True, ge=1)
        self.max_steps = check("max_steps_per_waypoint", max_steps_per_waypoint, integer=True, ge=1)
        self.follower = PurePursuit()
        self.bumps = np.zeros((0, 0), bool)
        self.path = np.zeros((0, 2))
        self.goal = np.zeros(2)
        self.steps = 0
        self.active = self._backing_off = False

    def reset(self) -> None:
        """Forget the last episode's bumps."""
        self.bumps = np.zeros((0, 0), bool)
        self.active = self._backing_off = False

    def start(self, view: RobotView, action: int) -> None:
        """Plan from the robot's view to coarse cell ``action``."""
        grid = view.grid
        if self.bumps.shape != grid.shape:
            self.bumps = np.zeros(grid.shape, bool)
        self._grid, self._radius_m = grid, float(view.radius_m)
        self._reverse = view.action_type == "continuous"
        self.goal = waypoint_goal_xy(grid, self.grid_cells, action)
        self.path = plan_path(
            view.belief_u8, grid, self._radius_m, view.odometry_pose, self.goal, self.bumps
        )
        self.follower.set_path(self.path)
        self.steps = 0
        self.active, self._backing_off = True, False
        self._drove_forward = False

    def command(self, pose: tuple[float, float, float], bumped: bool) -> tuple[float, float] | None:
        """(linear, angular) for the next step, or None when the waypoint is over.

        ``bumped``: whether the previous step touched a wall.
        """
        if not self.active:
            return None
        if self._backing_off or self.steps >= self.max_steps:
            self.active = False
            return None
        if self.steps > 0 and bumped and self._drove_forward:
            mark_contact(self.bumps, self._grid, pose, self._radius_m)
            self.follower.set_path(np.zeros((0, 2)))
            if not self._reverse:
                self.active = False
                return None
            self._backing_off = True
            self.steps += 1
            return -1.0, 0.0
        linear, angular = self.follower.command(pose)
        if not self.follower.has_path and self.steps > 0:
            self.active = False
            return None
        self.steps += 1
        # a continuous command always moves the robot; a discrete one only as "forward"
        self._drove_forward = self._reverse or to_discrete(linear, angular) == 0
        return linear, angular

    @property
    def reached(self) -> bool:
        """Whether the current (or last) waypoint's path was driven to its end."""
        return len(self.path) > 0 and not self.follower.has_path and not self._backing_off


def waypoint_goal_xy(grid: GridSpec, grid_cells: int, action: int | np.ndarray) -> np.ndarray:
    """World (x, y) of the centre of coarse cell ``action`` (row ``action // grid_cells``);
    ``(..., 2)`` for an array of actions.

    The coarse cells tile the square that the observation's ``map`` image shows (the grid
    fitted with its aspect kept and centred), so action ``a`` names the same block of pixels
    in every episode: rows grow with y, columns with x.
    """
    x0, y0, x1, y1 = grid.bounds
    side = max(x1 - x0, y1 - y0)
    left, bottom = (x0 + x1 - side) / 2, (y0 + y1 - side) / 2
    row, col = np.divmod(np.asarray(action, np.int64), grid_cells)
    step = side / grid_cells
    return np.stack([left + (col + 0.5) * step, bottom + (row + 0.5) * step], axis=-1)


def plan_path(
    belief_u8: np.ndarray,
    grid: GridSpec,
    radius_m: float,
    pose: tuple[float, float, float],
    goal_xy: np.ndarray,
    blocked: np.ndarray | None = None,
) -> np.ndarray:
    """A world path on the belief map from ``pose`` to the reachable cell nearest ``goal_xy``.

    Believed walls (and ``blocked`` cells) are obstacles, unknown cells cost more than free
    ones; an empty (0, 2) array when nothing is reachable.
    """
    cost = traversal_costs(belief_u8, grid.resolution_m, radius_m, blocked=blocked)
    row, col = (int(v) for v in grid.world_to_cell(np.array(pose[:2])))
    start = (row, col)
    field = cost_field(free_start(cost, start), start, grid.resolution_m)
    reachable = field.reachable()
    if not reachable.any():
        return np.zeros((0, 2))
    rows, cols = np.nonzero(reachable)
    goal_rc = grid.world_to_cell(np.asarray(goal_xy, np.float64))
    nearest = np.argmin((rows - goal_rc[0]) ** 2 + (cols - goal_rc[1]) ** 2)
    return cells_to_world(grid, field.path((int(rows[nearest]), int(cols[nearest]))))


#: Per-block features of :func:`block_features`, in column order.
BLOCK_FEATURES = ("unknown", "free", "wall", "inside", "distance", "robot")


def block_features(
    belief_u8: np.ndarray, grid: GridSpec, pose: tuple[float, float, float], grid_cells: int
) -> np.ndarray:
    """``float32 (n², 6)``: per waypoint block, what the robot knows of it (row-major blocks).

    Columns (:data:`BLOCK_FEATURES`): the fractions of the block's grid cells believed unknown,
    free and wall; the fraction of the block inside the grid; the distance from the robot to
    the block's centre over the square's side; 1 for the robot's own block.
    """
    free, wall, unknown = belief_classes(belief_u8)
    rows, cols = grid.shape
    side = max(rows, cols)
    # the square the blocks tile, in cells, and each block's cell range (clipped to the grid)
    top, left = (rows - side) / 2, (cols - side) / 2
    edges_r = np.clip(np.round(top + np.arange(grid_cells + 1) * side / grid_cells), 0, rows)
    edges_c = np.clip(np.round(left + np.arange(grid_cells + 1) * side / grid_cells), 0, cols)
    block_area = (side / grid_cells) ** 2
    out = np.zeros((grid_cells * grid_cells, len(BLOCK_FEATURES)), np.float32)
    x0, y0, x1, y1 = grid.bounds
    centres = waypoint_goal_xy(grid, grid_cells, np.arange(grid_cells * grid_cells))
    out[:, 4] = np.hypot(centres[:, 0] - pose[0], centres[:, 1] - pose[1]) / max(x1 - x0, y1 - y0)
    robot_r, robot_c = (int(v) for v in grid.world_to_cell(np.array(pose[:2])))
    for b in range(grid_cells * grid_cells):
        i, j = divmod(b, grid_cells)
        r0, r1, c0, c1 = int(edges_r[i]), int(edges_r[i + 1]), int(edges_c[j]), int(edges_c[j + 1])
        n = max((r1 - r0) * (c1 - c0), 0)
        if n:
            out[b, 0] = unknown[r0:r1, c0:c1].mean()
            out[b, 1] = free[r0:r1, c0:c1].mean()
            out[b, 2] = wall[r0:r1, c0:c1].mean()
        out[b, 3] = n / block_area
        out[b, 5] = float(r0 <= robot_r < r1 and c0 <= robot_c < c1)
    return out
