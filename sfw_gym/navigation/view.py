"""What the robot knows at one step: the typed contract between the env and everything that
drives the robot (agents, the waypoint driver). Never the ground truth."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sfw_gym.mapping.grid import GridSpec


@dataclass(frozen=True)
class RobotView:
    """What the robot knows at one step (``SfWExploreEnv.robot_view()``).

    The arrays are read-only views of the env's state, valid until its next ``step`` or ``reset``:
    a view costs O(1), whatever the map size or episode length. Copy what you keep.

    Attributes:
        belief_u8: The belief map (0 wall, 255 free, 127 unknown), ``[row, col]``.
        log_odds: Log-odds of "occupied" per cell (float32); :attr:`probability` from it.
        grid: The map's geometry.
        odometry_pose: ``(x, y, θ)`` from odometry (m, rad), not the true pose.
        routers_xy: ``(R, 2)`` router positions (the robot knows its routers).
        rssi_history: ``(T, R)`` readings so far, dBm (``NOT_HEARD_DBM`` when not heard).
        odometry_trajectory: ``(T, 2)`` odometry positions where those readings were taken.
        bumped: Whether the last step bumped into something.
        radius_m: The robot's radius.
        max_linear_speed_m_s, max_angular_speed_rad_s, control_period_s: Its motion limits.
        action_type: ``"continuous"`` or ``"discrete"``.
    """

    belief_u8: np.ndarray
    log_odds: np.ndarray
    grid: GridSpec
    odometry_pose: tuple[float, float, float]
    routers_xy: np.ndarray
    rssi_history: np.ndarray
    odometry_trajectory: np.ndarray
    bumped: bool
    radius_m: float
    max_linear_speed_m_s: float
    max_angular_speed_rad_s: float
    control_period_s: float
    action_type: str

    @property
    def probability(self) -> np.ndarray:
        """P(occupied) per cell, float32 (computed on each access)."""
        return (1.0 / (1.0 + np.exp(-self.log_odds.astype(np.float64)))).astype(np.float32)

    @property
    def xy(self) -> np.ndarray:
        """Odometry position ``(x, y)``."""
        return np.array(self.odometry_pose[:2], np.float64)

    @property
    def cell(self) -> tuple[int, int]:
        """Grid cell ``(row, col)`` of the odometry position (clipped into the grid)."""
        r, c = self.grid.world_to_cell(self.xy)
        h, w = self.grid.shape
        return min(max(int(r), 0), h - 1), min(max(int(c), 0), w - 1)
