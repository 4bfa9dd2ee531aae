"""``sfw-gym demo``: frontier, cross-pass and the shipped learned explorer on fresh plans, as an
HTML report."""

from __future__ import annotations

import argparse
import time

from sfw_gym.cli.options import (
    add_no_progress,
    add_out_folder,
    add_seed,
    add_workers,
    positive_int,
)

EXAMPLE = "sfw-gym demo --out sfw-report"
HELP = "frontier, cross-pass and the shipped learned explorer on fresh plans → sfw-report/"


def add_options(parser: argparse.ArgumentParser) -> None:
    from sfw_gym.demo import DEMO_EPISODES, DEMO_SEED

    add_out_folder(parser, "sfw-report", "report folder")
    parser.add_argument("--episodes", type=positive_int, default=DEMO_EPISODES, help="floorplans")
    add_seed(parser, "seed of the first floorplan", default=DEMO_SEED)
    add_workers(parser)
    parser.add_argument(
        "--model",
        default=None,
        help="a `sfw-gym train ppo_mask` folder or .zip (default: the shipped one)",
    )
    add_no_progress(parser)


def run(args: argparse.Namespace) -> int:
    from sfw_gym.demo import run_demo

    start = time.perf_counter()
    index = run_demo(
        args.out,
        args.episodes,
        args.seed,
        workers=args.workers,
        progress=not args.no_progress,
        model=args.model,
    )
    print(index.parent.joinpath("results.md").read_text(encoding="utf-8"), end="")
    html = index.with_suffix(".html")
    print(f"report: {index} ({time.perf_counter() - start:.0f} s); open {html} in a browser")
    return 0
