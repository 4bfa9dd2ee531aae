"""Every setting of an SfW-Explore env as one tree (:class:`EnvConfig`), read once from the
``gym.make`` keyword arguments and written back as them (:meth:`EnvConfig.to_kwargs`)."""

from __future__ import annotations

from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any, ClassVar

from sfw_gym.core.config import Config, setting, unknown_key_error
from sfw_gym.core.errors import ConfigError
from sfw_gym.mapping import MapperConfig
from sfw_gym.slam import RadioSlamConfig
from sfw_gym.world import RadioConfig, RobotConfig
from sfw_gym.world.generator import GeneratorConfig
from sfw_gym.world.lidar import LidarConfig
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


#: The ``gym.make`` keywords that are dicts of a subsystem's overrides.
SUBSYSTEMS = ("generator", "radio", "robot", "mapper", "slam", "lidar")


@dataclass(frozen=True)
class EnvConfig:
    """The env's whole configuration: its own settings, the reward, and each subsystem's config.

    Built once by :meth:`from_kwargs` (which fills the defaults that depend on other settings:
    the mapper's no-wall level from the radio, Radio SLAM's odometry weights from the robot's
    noise); :meth:`to_kwargs` gives keyword arguments that build the same env.
    """

    explore: ExploreConfig
    reward: RewardConfig
    floorplan: int | str | None
    generator: GeneratorConfig
    radio: RadioConfig
    robot: RobotConfig
    mapper: MapperConfig
    slam: RadioSlamConfig
    lidar: LidarConfig | None  # None: no LiDAR

    @classmethod
    def from_kwargs(cls, floorplan: Any = None, **kwargs: Any) -> EnvConfig:
        """The tree from ``gym.make`` keywords (see ``SfWExploreEnv``); a ConfigError names an
        unknown keyword with the nearest valid one."""
        flat = {f.name for f in fields(ExploreConfig)} | {f.name for f in fields(RewardConfig)}
        for key in kwargs:
            if key not in flat and key not in SUBSYSTEMS:
                raise unknown_key_error(
                    "SfW-Explore kwargs", key, [*flat, *SUBSYSTEMS, "floorplan"]
                )
        explore = ExploreConfig(**{k: v for k, v in kwargs.items() if k in _fields(ExploreConfig)})
        reward = RewardConfig(**{k: v for k, v in kwargs.items() if k in _fields(RewardConfig)})
        sub = {name: _overrides(name, kwargs.get(name)) for name in SUBSYSTEMS}
        radio = RadioConfig.preset(explore.radio_preset, band=explore.radio_band, **sub["radio"])
        robot = RobotConfig.from_dict(sub["robot"], "robot")
        # The robot knows its routers: their RSSI at 1 m with no wall (P_tx − PL(1 m)) calibrates
        # k = 0, so a router first heard through a wall is not read one wall short
        # (distance-aware estimation only: raw RSSI has no fixed no-wall level).
        mapper_defaults: dict[str, Any] = {"robot_radius_m": robot.radius_m}
        if sub["mapper"].get("k_estimator", "distance_aware") == "distance_aware":
            mapper_defaults["k0_level_dbm"] = radio.tx_power_dbm - radio.d0_loss_db
        # Radio SLAM weighs odometry by the robot's own noise model (per step, at full speed).
        full_step_m = robot.max_linear_speed_m_s * robot.control_period_s
        slam_defaults = {
            "odometry_sigma_m": max(robot.odometry_translation_std * full_step_m, 1e-3),
            "odometry_sigma_rad": max(robot.odometry_heading_std_rad, 1e-3),
        }
        lidar = kwargs.get("lidar")
        config = cls(
            explore=explore,
            reward=reward,
            floorplan=str(floorplan) if isinstance(floorplan, Path) else floorplan,
            generator=GeneratorConfig.from_dict(sub["generator"], "generator"),
            radio=radio,
            robot=robot,
            mapper=MapperConfig.from_dict({**mapper_defaults, **sub["mapper"]}, "mapper"),
            slam=RadioSlamConfig.from_dict({**slam_defaults, **sub["slam"]}, "slam"),
            lidar=None if lidar is None else LidarConfig.from_dict(lidar, "lidar"),
        )
        if explore.pose_source == "radio_lidar" and config.lidar is None:
            raise ConfigError("pose_source='radio_lidar' matches LiDAR scans: pass lidar={} (on)")
        return config

    def to_kwargs(self) -> dict[str, Any]:
        """JSON-serialisable ``gym.make`` keywords: ``gym.make(id, **to_kwargs())`` builds the
        same env (every subsystem in full, so a changed default cannot change a logged run)."""
        return {
            **self.explore.to_dict(),
            **self.reward.to_dict(),
            "floorplan": self.floorplan,
            "generator": self.generator.to_dict(),
            "radio": self.radio.to_dict(),
            "robot": self.robot.to_dict(),
            "mapper": self.mapper.to_dict(),
            "slam": self.slam.to_dict(),
            "lidar": None if self.lidar is None else self.lidar.to_dict(),
        }


def _fields(cls: type) -> set[str]:
    return {f.name for f in fields(cls)}


def _overrides(name: str, values: Any) -> dict[str, Any]:
    if values is None:
        return {}
    if not isinstance(values, dict):
        raise ConfigError(f"{name} must be a dict of overrides, got {type(values).__name__}")
    return values
