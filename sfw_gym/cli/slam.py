"""``sfw-gym slam``: Radio SLAM on a recorded log (CSV), optionally recorded first from a
frontier run: the corrected trajectory and a fingerprint map."""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from sfw_gym.cli.options import (
    add_env,
    add_out_folder,
    positive_float,
    positive_int,
    seed_int,
)
from sfw_gym.core.errors import ConfigError

if TYPE_CHECKING:
    from sfw_gym.slam import RadioSlamConfig

EXAMPLE = "sfw-gym slam drift.csv --record 7"
HELP = "Radio SLAM on a recorded log (CSV): corrected trajectory, fingerprint map"


def add_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "log", help="CSV: time, odom_x, odom_y, odom_theta, one column per AP [, true_x, true_y]"
    )
    parser.add_argument(
        "--record",
        type=seed_int,
        default=None,
        metavar="SEED",
        help="first record LOG: a frontier run on --env from this seed",
    )
    add_env(parser, "SfW-ExploreDrift-v0", "env id for --record (needs background APs)")
    parser.add_argument("--steps", type=positive_int, default=1500, help="steps for --record")
    parser.add_argument(
        "--keyframes", type=positive_int, default=5, help="every k-th pose a graph node"
    )
    for option, what, unit in (
        ("--odometry-sigma", "translation", "metres"),
        ("--heading-sigma", "heading", "radians"),
    ):
        parser.add_argument(
            option,
            type=positive_float,
            default=None,
            help=f"odometry's {what} error per pose, {unit} (default: 0.02; --record: the env's)",
        )
    add_out_folder(parser, None, "output folder (default: LOG_slam/)")


def run(args: argparse.Namespace) -> int:
    from sfw_gym.slam import RadioSlamConfig
    from sfw_gym.slam.offline import slam_log, trajectory_errors

    settings = {"keyframe_every": args.keyframes}
    if args.record is not None:  # odometry weighted by the recording robot's noise model
        recorded = _record_slam_log(args.log, args.env, args.record, args.steps)
        settings |= {k: getattr(recorded, k) for k in ("odometry_sigma_m", "odometry_sigma_rad")}
        print(
            f"recorded {args.steps} frontier steps on {args.env} (seed {args.record}) to {args.log}"
        )
    if args.odometry_sigma is not None:
        settings["odometry_sigma_m"] = args.odometry_sigma
    if args.heading_sigma is not None:
        settings["odometry_sigma_rad"] = args.heading_sigma
    out = args.out or str(Path(args.log).with_suffix("")) + "_slam"
    start = time.perf_counter()
    log, result, paths = slam_log(args.log, out, RadioSlamConfig(**settings))
    print(
        f"{log.path}: {len(log.odometry)} poses, {len(log.access_points)} access points, "
        f"{len(result.closures)} radio loop closures; {time.perf_counter() - start:.1f} s"
    )
    errors = trajectory_errors(log, result)
    if errors:
        print(
            f"ATE (against the log's truth): odometry {errors[0]:.2f} m, "
            f"Radio SLAM {errors[1]:.2f} m"
        )
    print(f"wrote {paths['trajectory']}, {paths['fingerprint_map']}, {paths['figure']}")
    return 0


def _record_slam_log(path: str, env_id: str, seed: int, steps: int) -> RadioSlamConfig:
    """A frontier run on ``env_id`` written as a Radio SLAM log with its truth; returns the
    env's Radio SLAM settings (its odometry weights follow the robot's noise)."""
    import gymnasium as gym

    from sfw_gym.envs.explore import unwrap_sfw
    from sfw_gym.evaluation.drives import record_frontier_drive
    from sfw_gym.slam.offline import write_slam_log

    if not unwrap_sfw(gym.make(env_id)).config.explore.n_background_aps:
        raise ConfigError(f"--env {env_id}: has no background access points to fingerprint")
    drive = record_frontier_drive(env_id, seed, steps)
    write_slam_log(
        path,
        drive["period_s"] * np.arange(len(drive["truth"])),
        drive["odometry"],
        drive["fingerprints"],
        drive["truth"],
    )
    return drive["slam_config"]
