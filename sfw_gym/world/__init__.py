"""Ground truth of the simulation: floorplans, the radio model, the robot and its LiDAR.

Knows nothing of `sfw_gym.mapping`, `sfw_gym.envs` or `sfw_gym.agents`.
"""

from __future__ import annotations

from sfw_gym.world.floorplan import (
    MATERIALS,
    Floorplan,
    Room,
    floorplan_from_polygon,
    load_floorplan,
)
from sfw_gym.world.generator import generate_floorplan
from sfw_gym.world.lidar import Lidar, LidarConfig
from sfw_gym.world.radio import RadioConfig, RadioModel
from sfw_gym.world.robot import Pose, Robot, RobotConfig, StepResult
from sfw_gym.world.routers import place_background_aps, place_routers

__all__ = [
    "MATERIALS",
    "Floorplan",
    "Lidar",
    "LidarConfig",
    "Pose",
    "RadioConfig",
    "RadioModel",
    "Robot",
    "RobotConfig",
    "Room",
    "StepResult",
    "floorplan_from_polygon",
    "generate_floorplan",
    "load_floorplan",
    "place_background_aps",
    "place_routers",
]
