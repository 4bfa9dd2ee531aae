"""Radio SLAM on real WiFine scans over synthetic odometry, against the odometry (issue 38).

Each train walk's real fingerprints, odometry made from its true positions at a noise level
(translation std per metre, heading std per step; seeded per walk and seed), Radio SLAM with
:func:`sfw_gym.slam.real_walks.real_walk_config`; ATE (m, aligned) of both, and the closures
Radio SLAM kept, judged against the true distance between their scans (wrong: off by more than
3 of their sigmas or more than 3 m).

    python scripts/benchmarks/bench_wifine_slam.py             # all 120 train walks, seeds 0 1 2
    python scripts/benchmarks/bench_wifine_slam.py --walks 15 --seeds 0 --levels 0.05:0.02

Results: docs/results/slam.md#radio-slam-on-real-wifine-scans.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from sfw_gym.datasets import read_wifine
from sfw_gym.slam.real_walks import (
    REAL_WALK_SETTINGS,
    WRONG_ERROR_M,
    WRONG_SIGMAS,
    real_walk_config,
    slam_on_walks,
)

ROOT = Path(__file__).resolve().parents[2]


def level(text: str) -> tuple[float, float]:
    """``"0.05:0.02"`` → (translation std per metre, heading std per step in rad)."""
    translation, heading = text.split(":")
    return float(translation), float(heading)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--wifine", default=str(ROOT.parent / "shared/datasets/wifine"))
    parser.add_argument("--split", default="train")
    parser.add_argument("--walks", type=int, default=None, help="evenly spaced, default all")
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    parser.add_argument(
        "--levels", type=level, nargs="+", default=[(0.05, 0.02), (0.10, 0.04)],
        help="noise levels TRANSLATION_STD:HEADING_STD_RAD",
    )  # fmt: skip
    parser.add_argument(
        "--set", nargs="*", default=[], metavar="FIELD=VALUE",
        help="override REAL_WALK_SETTINGS (tuning), e.g. heading_snap_deg=180",
    )  # fmt: skip
    args = parser.parse_args()
    overrides = {
        k: int(v) if v.lstrip("-").isdigit() else float(v)
        for k, v in (item.split("=") for item in args.set)
    }

    data = read_wifine(Path(args.wifine) / args.split)
    labels = sorted(label for label, _ in data.walks())
    if args.walks is not None and args.walks < len(labels):
        labels = [
            labels[k] for k in np.linspace(0, len(labels) - 1, args.walks).round().astype(int)
        ]
    print(f"{len(labels)} {args.split} walks of {args.wifine}, seeds {args.seeds}")
    print(f"settings: {REAL_WALK_SETTINGS | overrides}")
    print(
        f"wrong closure: off the true distance by > {WRONG_SIGMAS:g} sigma or > {WRONG_ERROR_M:g} m"
    )
    for translation, heading in args.levels:
        config = real_walk_config(translation, heading, **overrides)
        start = time.perf_counter()
        runs = [
            r
            for seed in args.seeds
            for r in slam_on_walks(
                data,
                translation_std=translation,
                heading_std_rad=heading,
                seed=seed,
                config=config,
                labels=labels,
            )
        ]
        seconds = time.perf_counter() - start
        odo = np.array([r.ate_odometry_m for r in runs])
        slam = np.array([r.ate_slam_m for r in runs])
        closures = np.array([r.n_closures for r in runs])
        wrong = np.array([r.n_wrong for r in runs])
        true_m = np.concatenate([r.closure_true_m for r in runs])
        error = np.abs(np.concatenate([r.closure_true_m - r.closure_distance_m for r in runs]))
        bad = np.concatenate([r.wrong for r in runs])
        lines = sum(r.n_corridor for r in runs)
        wrong_lines = sum(r.n_wrong_corridor for r in runs)
        turns = sum(r.n_turns for r in runs)
        wrong_turns = sum(r.n_wrong_turns for r in runs)
        print(f"\n### odometry noise {translation:g} per m, {heading:g} rad per step")
        print(
            f"{len(runs)} runs ({len(labels)} walks x {len(args.seeds)} seeds), {seconds:.0f} s\n"
        )
        print(
            "| walks x seeds | ATE odometry mean / median (m) | ATE Radio SLAM mean / median (m)"
            " | ratio of means | runs SLAM < odometry | closures per walk | wrong closures |"
        )
        print("|---|---|---|---|---|---|---|")
        print(
            f"| {len(labels)} x {len(args.seeds)} | {odo.mean():.2f} / {np.median(odo):.2f} | "
            f"{slam.mean():.2f} / {np.median(slam):.2f} | **{slam.mean() / odo.mean():.3f}** | "
            f"{np.mean(slam < odo):.0%} | {closures.mean():.1f} | "
            f"{wrong.sum()} of {closures.sum()} ({wrong.sum() / max(closures.sum(), 1):.1%}) |"
        )
        if lines:
            lateral = np.concatenate(
                [r.corridor_true_m[r.corridor] for r in runs if r.corridor is not None]
            )
            print(
                f"\ncorridor closures: {lines} ({lines / len(runs):.1f} per walk), true lateral "
                f"offset median {np.median(lateral):.2f} m, p90 {np.percentile(lateral, 90):.2f} "
                f"m; wrong (off the line by > 3 sigma or > 3 m) {wrong_lines} "
                f"({wrong_lines / lines:.1%})"
            )
        if turns:
            print(
                f"\nheading closures: {turns} ({turns / len(runs):.1f} per walk), wrong turn "
                f"(off the true one by > 45 deg) {wrong_turns} ({wrong_turns / turns:.1%})"
            )
        if len(true_m):
            print(
                f"\nclosures: true distance median {np.median(true_m):.1f} m, p90 "
                f"{np.percentile(true_m, 90):.1f} m; estimate error median "
                f"{np.median(error):.1f} m; right ones' true distance median "
                f"{np.median(true_m[~bad]):.1f} m, wrong ones' "
                f"{np.median(true_m[bad]) if bad.any() else float('nan'):.1f} m "
                f"(p90 {np.percentile(true_m[bad], 90) if bad.any() else float('nan'):.1f} m); "
                f"runs with no closure {np.mean(closures == 0):.0%}; per-run ratio median "
                f"{np.median(slam / odo):.2f}"
            )


if __name__ == "__main__":
    main()
