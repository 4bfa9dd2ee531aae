"""The env's own settings (beside the radio, robot, mapper and generator configs it composes)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from sfw_gym.core.config import Config, setting
from sfw_gym.core.errors import ConfigError
from sfw_gym.world.radio import BANDS, PRESETS

ACTION_TYPES = ("continuous", "discrete")
#: Where the robot believes it is, and so where it maps: its odometry, Radio SLAM (odometry
#: corrected by radio loop closures, the map rebuilt along each correction), Radio+LiDAR SLAM
#: (also LiDAR scan matching; needs the LiDAR), or the truth.
POSE_SOURCES = ("odometry", "radio_slam", "radio_lidar", "true")
#: Keys of ``reset(options=...)``.
RESET_OPTIONS = ("floorplan", "routers", "start_pose")


@dataclass(frozen=True)
class RewardConfig(Config):
    """What the env pays for: ``reward_scale`` × the map's information gain (bits) − a
    ``collision_penalty`` per bump; the episode ends once ``coverage_target`` is reached."""

    prefix: ClassVar[str | None] = ""  # gym.make keyword arguments

    reward_scale: float = setting(0.01, ge=0.0, le=1e6)
    collision_penalty: float = setting(0.1, ge=0.0, le=1e6)
    coverage_target: float = setting(0.95, ge=0.0, le=1.0)


@dataclass(frozen=True)
class ExploreConfig(Config):
    """Actions, routers, the map's resolution, observation sizes and the step budget
    (``steps_per_m2``: None, or a budget of ``min(max_steps, ceil(steps_per_m2 × free area))``);
    ``n_background_aps`` access points beyond the routers, heard as a fingerprint."""

    prefix: ClassVar[str | None] = ""  # gym.make keyword arguments

    action_type: str = setting("continuous", choices=ACTION_TYPES)
    n_routers: int = setting(2, integer=True, ge=1, le=16)
    radio_preset: str = setting("default", choices=PRESETS)
    radio_band: str = setting("2.4", choices=tuple(BANDS))
    resolution_m: float = setting(0.1, ge=0.02, le=1.0)
    map_px: int = setting(64, integer=True, ge=36, le=512)
    crop_px: int = setting(48, integer=True, ge=36, le=512)
    max_steps: int = setting(3000, integer=True, ge=1, le=10**7)
    steps_per_m2: float | None = setting(None, optional=True, ge=1e-3, le=1e5)
    n_background_aps: int = setting(0, integer=True, ge=0, le=64)
    pose_source: str = setting("odometry", choices=POSE_SOURCES)

    def validate(self) -> None:
        if self.pose_source in ("radio_slam", "radio_lidar") and self.n_background_aps < 1:
            raise ConfigError(
                f"pose_source={self.pose_source!r} closes loops with background access points: "
                "pass n_background_aps >= 1 (SfW-ExploreRadioSLAM-v0 has 16)"
            )
