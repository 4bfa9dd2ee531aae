"""``sfw-gym localize``: the WiFi Monte-Carlo localisation study on Gaussian gridmaps (the
paper's tables)."""

from __future__ import annotations

import argparse

from sfw_gym.cli.options import add_episode_runner_options, folder, positive_int, runner_settings

EXAMPLE = "sfw-gym localize --plans 10 --out localize"
HELP = "WiFi Monte-Carlo localisation on Gaussian gridmaps: the paper's tables → OUT/"


def add_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--plans", type=positive_int, default=10, help="held-out plans")
    parser.add_argument(
        "--runs", type=positive_int, default=3, help="MCL runs per plan and setting"
    )
    parser.add_argument(
        "--survey-steps", type=positive_int, default=2000, help="steps of each survey drive"
    )
    parser.add_argument(
        "--test-steps", type=positive_int, default=400, help="steps of each test drive"
    )
    parser.add_argument("--particles", type=positive_int, default=500, help="particles")
    parser.add_argument(
        "--no-direct", action="store_true", help="skip MCL on direct GP prediction (the slow part)"
    )
    add_episode_runner_options(parser)
    parser.add_argument(
        "--out",
        "--json",  # its name before 0.2.0, kept as an alias
        dest="out",
        type=folder,
        default="localize",
        help="output folder; --json is its old name",
    )


def run(args: argparse.Namespace) -> int:
    from sfw_gym.evaluation.localization import run_localization_study

    study = ("plans", "runs", "survey_steps", "test_steps", "particles")
    summary = run_localization_study(
        args.out,
        direct=not args.no_direct,
        **{name: getattr(args, name) for name in study},
        **runner_settings(args),
    )
    print(summary["markdown"])
    print(f"wrote {args.out}/results.json, tables.md, gridmaps.png, error_over_time.png")
    return 0
