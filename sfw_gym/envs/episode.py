"""One episode's world: floorplan, routers and radio, robot, and the ground-truth grid."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import ndimage

from sfw_gym.core.config import float_array
from sfw_gym.core.constants import U8_FREE
from sfw_gym.core.errors import ConfigError
from sfw_gym.mapping import GridSpec
from sfw_gym.world import (
    Floorplan,
    RadioConfig,
    RadioModel,
    Robot,
    RobotConfig,
    generate_floorplan,
    load_floorplan,
    place_background_aps,
    place_routers,
)
from sfw_gym.world.floorplan import chosen_routers

#: Start poses keep this much more than the robot's radius from every wall.
START_CLEARANCE_MARGIN_M = 0.05


@dataclass
class EpisodeScene:
    """Ground truth of one episode (never shown to agents, only to the env and its info)."""

    floorplan: Floorplan
    radio: RadioModel
    robot: Robot
    truth_u8: np.ndarray  # 0 wall, 255 free, 127 outside
    grid_origin: tuple[float, float]
    background: RadioModel | None = None  # access points beyond the routers (their fingerprint)


@dataclass(frozen=True)
class GroundTruth:
    """What the simulator knows and the robot does not, for evaluation and figures (agents get
    :class:`~sfw_gym.navigation.view.RobotView` only).

    Attributes:
        floorplan: The episode's plan.
        truth_u8: Ground-truth grid on the belief map's cells (0 wall, 255 free, 127 outside).
        grid: The belief map's geometry.
        radio: The radio model (routers, noise-free ``mean_rssi``).
        trajectory: ``(T, 2)`` true positions so far.
        pose: The true pose now, ``(x, y, θ)`` (m, rad).
    """

    floorplan: Floorplan
    truth_u8: np.ndarray
    grid: GridSpec
    radio: RadioModel
    trajectory: np.ndarray
    pose: tuple[float, float, float]


def resolve_floorplan(source: Any, generator_params: dict[str, Any] | None = None) -> Floorplan:
    """A Floorplan from a Floorplan, a generator seed (int) or a plan file's path (JSON, or a
    ROS map's YAML: :func:`~sfw_gym.world.load_floorplan`)."""
    if isinstance(source, Floorplan):
        return source
    if isinstance(source, int | np.integer) and not isinstance(source, bool):
        return generate_floorplan(int(source), **(generator_params or {}))
    if isinstance(source, str | os.PathLike):
        return load_floorplan(source)
    raise ConfigError(
        "floorplan must be a Floorplan, a generator seed (int) or a plan file's path, got "
        f"{source!r:.80}"
    )


def build_scene(
    floorplan: Any,
    *,
    routers: Any,
    max_routers: int,
    start_pose: Any,
    radio_config: RadioConfig,
    robot_config: RobotConfig,
    resolution_m: float,
    rng: np.random.Generator,
    generator_params: dict[str, Any] | None = None,
    n_background_aps: int = 0,
) -> EpisodeScene:
    """Assemble an episode; every random choice comes from ``rng`` (the background access
    points' last, so that without them every other draw is as before). ``routers`` None: the
    plan's own (:attr:`Floorplan.routers`), else ``max_routers`` placed by k-means."""
    plan = resolve_floorplan(floorplan, generator_params)
    routers = chosen_routers(routers, plan, max_routers)
    truth, origin = plan.rasterize(resolution_m)
    if isinstance(routers, int | np.integer) and not isinstance(routers, bool):
        if not 1 <= routers <= max_routers:
            raise ConfigError(f"routers: a count must be in [1, {max_routers}], got {routers}")
        routers = place_routers(plan, int(routers), rng)
    routers = float_array("routers", routers)
    if routers.ndim == 2 and len(routers) > max_routers:
        raise ConfigError(
            f"routers: {len(routers)} positions given, the env was made for at most {max_routers} "
            f"(its observation has {max_routers} router slots; pass n_routers to gym.make)"
        )
    radio = RadioModel(plan, routers, radio_config, rng)
    pose = start_pose_in(plan, truth, origin, resolution_m, robot_config.radius_m, start_pose, rng)
    robot = Robot(plan.edges, robot_config, pose, rng)
    background = None
    if n_background_aps:
        aps = place_background_aps(plan, n_background_aps, rng)
        background = RadioModel(plan, aps, radio_config, rng, in_free_space=False)
    return EpisodeScene(plan, radio, robot, truth, origin, background)


def start_pose_in(
    plan: Floorplan,
    truth: np.ndarray,
    origin: tuple[float, float],
    resolution_m: float,
    radius_m: float,
    start_pose: Any,
    rng: np.random.Generator,
) -> tuple[float, float, float]:
    """``start_pose`` checked, or (None) a random free pose with clearance for the robot."""
    if start_pose is not None:
        pose = float_array("start_pose", start_pose)
        if pose.shape != (3,) or not np.isfinite(pose).all():
            raise ConfigError(
                f"start_pose must be three finite numbers (x, y, θ), got {start_pose!r}"
            )
        if not plan.is_free(pose[:2]):
            raise ConfigError(
                f"start_pose {pose[:2].tolist()} is not in the free space of {plan.name!r}"
            )
        return float(pose[0]), float(pose[1]), float(pose[2])
    clearance = ndimage.distance_transform_edt(truth == U8_FREE) * resolution_m
    rows, cols = np.nonzero(clearance >= radius_m + START_CLEARANCE_MARGIN_M + resolution_m)
    if len(rows) == 0:
        raise ConfigError(f"floorplan {plan.name!r} has no spot wide enough for the robot")
    i = int(rng.integers(len(rows)))
    x = origin[0] + (cols[i] + 0.5) * resolution_m
    y = origin[1] + (rows[i] + 0.5) * resolution_m
    return x, y, float(rng.uniform(-math.pi, math.pi))
