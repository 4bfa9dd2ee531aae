"""``sfw-gym fingerprints``: WiFi fingerprint localisation on real surveys (CSV):
``fingerprints evaluate`` fits on one survey and locates another (optionally tracking each walk
with MCL); ``fingerprints convert`` turns a public dataset into the generic CSV."""

from __future__ import annotations

import argparse

from sfw_gym.cli.options import (
    add_command,
    add_seed,
    folder,
    non_negative_float,
    positive_int,
    unit_float,
)
from sfw_gym.core.errors import ConfigError

EXAMPLE = "sfw-gym fingerprints evaluate --train train.csv --test test.csv --out fp"
HELP = "WiFi fingerprint localisation on real surveys (CSV): evaluate, or convert a dataset"
DESCRIPTION = (
    "sfw-gym fingerprints evaluate --train TRAIN.csv --test TEST.csv --out DIR | "
    "sfw-gym fingerprints convert --format FORMAT SOURCE OUT.csv"
)


def parse_floorplan_option(text: str) -> tuple[int | None, str]:
    """``--floorplan``: ``PATH`` (every floor) or ``FLOOR=PATH``."""
    floor, sep, path = text.partition("=")
    if sep and floor.strip().lstrip("-").isdigit():
        return int(floor), path
    return None, text


def add_options(parser: argparse.ArgumentParser) -> None:
    from sfw_gym.datasets.readers import UJI_SPLITS

    actions = parser.add_subparsers(dest="action", metavar="{evaluate,convert}", required=True)
    _add_evaluate_parser(actions)
    conv = add_command(
        actions, "convert", run, help="a dataset in its own layout → the generic CSV"
    )
    conv.add_argument("--format", required=True, choices=["csv", "ujiindoorloc", "wifine"])
    conv.add_argument(
        "--split", default="train", choices=sorted(UJI_SPLITS), help="UJIIndoorLoc's split"
    )
    _add_not_heard(conv, "csv: the value meaning not heard")
    conv.add_argument("source", help="UJIIndoorLoc's zip, a WiFine CSV or folder, or a CSV")
    conv.add_argument("output", help="the generic CSV to write")


def _add_not_heard(parser: argparse.ArgumentParser, help: str) -> None:
    from sfw_gym.datasets.readers import GENERIC_NOT_HEARD

    parser.add_argument("--not-heard", type=float, default=GENERIC_NOT_HEARD, help=help)


def _add_evaluate_parser(actions: argparse._SubParsersAction) -> None:
    from sfw_gym.datasets import DRIFT_HEADING_STD_RAD, DRIFT_TRANSLATION_STD
    from sfw_gym.localization.fingerprinting import DEFAULT_METHOD, METHODS
    from sfw_gym.localization.tracking import TRACK_PARTICLES, WALL_WEIGHT

    ev = add_command(
        actions,
        "evaluate",
        run,
        help="fit on TRAIN, locate TEST → DIR/metrics.json, DIR/predictions.csv",
        description="CSV: a header; x, y (metres); optional floor, building (integers), "
        "trajectory (a label), t (seconds); every other column one access point's RSSI in dBm, "
        "--not-heard or an empty cell meaning not heard. --track: the test rows of each "
        "trajectory, in t order, are one walk; its odometry is SYNTHETIC (the true positions "
        "plus noise), and WiFi MCL on the Gaussian gridmaps tracks it.",
    )
    ev.add_argument("--train", required=True, help="training fingerprints (CSV)")
    ev.add_argument("--test", required=True, help="test fingerprints (CSV)")
    ev.add_argument("--out", type=folder, required=True, help="output folder")
    ev.add_argument(
        "--method", default=DEFAULT_METHOD, choices=METHODS, help="the localisation method"
    )
    _add_not_heard(ev, "the value meaning not heard")
    ev.add_argument("--track", action="store_true", help="track each test trajectory (MCL)")
    ev.add_argument(
        "--floorplan",
        type=parse_floorplan_option,
        action="append",
        default=[],
        metavar="[FLOOR=]PLAN",
        help="with --track: particles keep to this plan's free space (a ROS map .yaml or a "
        "plan JSON); FLOOR=PLAN for one floor, repeatable",
    )
    ev.add_argument(
        "--wall-weight",
        type=unit_float,
        default=WALL_WEIGHT,
        help="with --floorplan: the share of its weight a particle keeps when it crosses a wall "
        "(0: walls are uncrossable; above 0 where the plan may be wrong)",
    )
    ev.add_argument(
        "--odometry-translation-std",
        type=non_negative_float,
        default=DRIFT_TRANSLATION_STD,
        help="synthetic odometry: translation noise per metre walked",
    )
    ev.add_argument(
        "--odometry-heading-std-rad",
        type=non_negative_float,
        default=DRIFT_HEADING_STD_RAD,
        help="synthetic odometry: heading noise per step (rad)",
    )
    add_seed(ev, "the odometry and particles' seed")
    ev.add_argument(
        "--particles", type=positive_int, default=TRACK_PARTICLES, help="particles per walk"
    )


def run(args: argparse.Namespace) -> int:
    from sfw_gym.datasets import read_csv, read_ujiindoorloc, read_wifine

    if args.action == "convert":
        if args.format == "ujiindoorloc":
            data = read_ujiindoorloc(args.source, args.split)
        elif args.format == "wifine":
            data = read_wifine(args.source)
        else:
            data = read_csv(args.source, not_heard=args.not_heard)
        data.to_csv(args.output)
        print(f"wrote {args.output}: {len(data)} scans, {data.n_access_points} access points")
        return 0
    from sfw_gym.evaluation.fingerprints import TrackSettings, evaluate, write_evaluation
    from sfw_gym.world.floorplan import load_floorplan

    train = read_csv(args.train, not_heard=args.not_heard)
    test = read_csv(args.test, not_heard=args.not_heard)
    track = None
    if args.track:
        plans = {floor: load_floorplan(path) for floor, path in args.floorplan}
        track = TrackSettings(
            translation_std=args.odometry_translation_std,
            heading_std_rad=args.odometry_heading_std_rad,
            seed=args.seed,
            particles=args.particles,
            floorplans=plans,
            wall_weight=args.wall_weight,
        )
    elif args.floorplan:
        raise ConfigError("--floorplan: only used with --track")
    metrics, columns = evaluate(train, test, args.method, track)
    paths = write_evaluation(args.out, metrics, columns)
    print(_summary(metrics))
    print(f"wrote {paths['metrics']} and {paths['predictions']}")
    return 0


def _summary(metrics: dict) -> str:
    line = (
        f"{metrics['method']}: {metrics['n_test']} scans, mean error {metrics['mean_error_m']:.2f}"
        f" (median {metrics['median_error_m']:.2f}, p95 {metrics['p95_error_m']:.2f})"
    )
    if "per_scan_mean_error_m" in metrics:
        line += f", per scan {metrics['per_scan_mean_error_m']:.2f}"
    for key in ("floor_hit_rate", "building_hit_rate"):
        if key in metrics:
            line += f", {key.split('_')[0]} {100 * metrics[key]:.1f} %"
    return line + f"; fit {metrics['fit_s']:.1f} s, {metrics['query_ms_per_scan']:.2f} ms a scan"
