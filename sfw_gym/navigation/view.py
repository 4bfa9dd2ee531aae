"""What the robot knows at one step: the typed contract between the env and everything that
drives the robot (agents, the waypoint driver). Never the ground truth."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from sfw_gym.core.constants import NOT_HEARD_DBM
from sfw_gym.mapping.grid import GridSpec, belief_classes
from sfw_gym.mapping.sparse import MapperState
from sfw_gym.world.robot import RobotConfig


@dataclass(frozen=True)
class RobotView:
    """What the robot knows at one step (``SfWExploreEnv.robot_view()``).

    The arrays are read-only views of the env's state, valid until its next ``step`` or ``reset``:
    a view costs O(1), whatever the map size or episode length. Copy what you keep.

    Attributes:
        belief_u8: The belief map (0 wall, 255 free, 127 unknown), ``[row, col]``.
        log_odds: Log-odds of "occupied" per cell (float32); :attr:`probability` from it.
        grid: The map's geometry.
        odometry_pose: ``(x, y, θ)`` where the robot believes it is (m, rad), never the true
            pose: its odometry, or Radio SLAM's estimate (the env's ``pose_source``).
        routers_xy: ``(R, 2)`` router positions (the robot knows its routers).
        rssi_history: ``(T, R)`` readings so far, dBm (``NOT_HEARD_DBM`` when not heard).
        odometry_trajectory: ``(T, 2)`` positions (of that estimate) where those readings were
            taken.
        bumped: Whether the last step bumped into something.
        radius_m: The robot's radius.
        max_linear_speed_m_s, max_angular_speed_rad_s, control_period_s: Its motion limits.
        action_type: ``"continuous"`` or ``"discrete"``.
        mapper_state: The rest of the robot's own mapper (its trajectory raster and k
            thresholds, read-only): what a dry run of its update needs
            (:class:`~sfw_gym.mapping.dry_run.DryRun`); None on a hand-made view.
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
    mapper_state: MapperState | None = None

    @classmethod
    def hand_made(
        cls,
        belief_u8: np.ndarray,
        grid: GridSpec,
        pose: tuple[float, float, float],
        routers_xy: np.ndarray,
        *,
        rssi_history: np.ndarray | None = None,
        odometry_trajectory: np.ndarray | None = None,
        bumped: bool = False,
        robot: RobotConfig | None = None,
        action_type: str = "continuous",
    ) -> RobotView:
        """A view of a hand-made belief (tests, benchmarks, maps from elsewhere): log-odds ±3 for
        believed free / wall cells and 0 (one bit) for unknown ones; by default one reading,
        "not heard", taken at ``pose``; the default robot's size and limits."""
        belief = np.asarray(belief_u8, np.uint8)
        free, wall, _ = belief_classes(belief)
        routers = np.asarray(routers_xy, np.float64).reshape(-1, 2)
        robot = robot or RobotConfig()
        if rssi_history is None:
            rssi_history = np.full((1, len(routers)), NOT_HEARD_DBM, np.int32)
        if odometry_trajectory is None:
            odometry_trajectory = np.tile(np.asarray(pose[:2], np.float64), (len(rssi_history), 1))
        return cls(
            belief_u8=belief,
            log_odds=np.where(wall, 3.0, np.where(free, -3.0, 0.0)).astype(np.float32),
            grid=grid,
            odometry_pose=(float(pose[0]), float(pose[1]), float(pose[2])),
            routers_xy=routers,
            rssi_history=np.asarray(rssi_history),
            odometry_trajectory=np.asarray(odometry_trajectory, np.float64),
            bumped=bool(bumped),
            radius_m=robot.radius_m,
            max_linear_speed_m_s=robot.max_linear_speed_m_s,
            max_angular_speed_rad_s=robot.max_angular_speed_rad_s,
            control_period_s=robot.control_period_s,
            action_type=action_type,
        )

    @property
    def probability(self) -> np.ndarray:
        """P(occupied) per cell, float32 (computed on each access)."""
        return (1.0 / (1.0 + np.exp(-self.log_odds.astype(np.float64)))).astype(np.float32)

    @cached_property
    def xy(self) -> np.ndarray:
        """Odometry position ``(x, y)`` (read-only)."""
        xy = np.array(self.odometry_pose[:2], np.float64)
        xy.flags.writeable = False
        return xy

    @cached_property
    def cell(self) -> tuple[int, int]:
        """Grid cell ``(row, col)`` of the odometry position (clipped into the grid)."""
        return self.grid.clipped_cell(self.xy)
