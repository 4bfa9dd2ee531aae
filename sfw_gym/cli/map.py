"""``sfw-gym map``: map a recorded RSSI log (CSV) offline, to a PNG, an .npy and a .json."""

from __future__ import annotations

import argparse

from sfw_gym.cli.options import non_negative_float, parse_routers, positive_float
from sfw_gym.core.errors import ConfigError

EXAMPLE = 'sfw-gym map LOG.csv --routers "60,60;220,220" --scale 0.05 --out map.png'
HELP = "map a recorded RSSI log (CSV) offline: PNG + .npy"


def add_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("log", help="CSV: x, y, then RSSI columns (the SfW experiments' layout)")
    parser.add_argument(
        "--routers", required=True, help="router positions 'x1,y1;x2,y2' in the CSV's units"
    )
    units = parser.add_mutually_exclusive_group()
    units.add_argument(
        "--scale",
        type=positive_float,
        default=None,
        help="metres per CSV unit (default: 1; pixels e.g. 0.05)",
    )
    units.add_argument(
        "--px-per-m",
        type=positive_float,
        default=None,
        help="CSV units (canvas pixels) per metre: the SfW logs' about 87 (0.0115 m per pixel)",
    )
    parser.add_argument(
        "--resolution", type=positive_float, default=0.05, help="map cell size, metres"
    )
    parser.add_argument(
        "--margin", type=non_negative_float, default=1.0, help="border around the data, metres"
    )
    parser.add_argument(
        "--rssi-column",
        default=None,
        metavar="max|2.4|5|NAME[,NAME...]",
        help="each router's RSSI: its strongest band (max), one band, or one column name per "
        "router (default: max, as the SfW authors mapped)",
    )
    parser.add_argument(
        "--policy",
        choices=["strongest", "all"],
        default=None,
        help="update along every heard router's ray (all) or the strongest's only (the paper) "
        "(default: all, measured best on two-router logs)",
    )
    parser.add_argument(
        "--method",
        choices=["inverse-k", "sfw-reference"],
        default="inverse-k",
        help="sparse inverse k-visibility (ours) or the SfW authors' method",
    )
    parser.add_argument(
        "--passes",
        type=int,
        choices=[1, 2],
        default=2,
        help="2: run the log forward, then reversed; 1: forward only",
    )
    parser.add_argument(
        "--score",
        action="store_true",
        help="score the map against the truth recorded beside the log (sfw-gym record)",
    )
    parser.add_argument(
        "--y-down", action="store_true", help="the CSV's y grows downward (image pixels)"
    )
    parser.add_argument("--out", default="map.png", help="output PNG; .npy and .json beside it")


def run(args: argparse.Namespace) -> int:
    from dataclasses import replace

    from sfw_gym.mapping.offline import OFFLINE_CONFIG, map_log, write_map

    routers = parse_routers(args.routers)
    if isinstance(routers, int):
        raise ConfigError(
            f"--routers: the map command needs router positions 'x1,y1;x2,y2' in the CSV's "
            f"units, not a count ({routers})"
        )
    result = map_log(
        args.log,
        routers,
        scale_m_per_unit=1.0 / args.px_per_m if args.px_per_m else (args.scale or 1.0),
        resolution_m=args.resolution,
        margin_m=args.margin,
        rssi_column=args.rssi_column,
        config=replace(OFFLINE_CONFIG, router_policy=args.policy or OFFLINE_CONFIG.router_policy),
        method=args.method,
        passes=args.passes,
    )
    paths = write_map(result, args.out, y_down=args.y_down)
    log = result.log
    rows, cols = result.grid.shape
    print(
        f"{log.path}: {log.n_samples} samples, {log.n_skipped} rows skipped (no position); "
        f"routers <- columns {', '.join(result.columns)}"
    )
    print(
        f"mapper: {result.median_us_per_sample:.1f} µs per sample (median; mean "
        f"{result.us_per_sample:.1f}), {cols} x {rows} cells of {result.grid.resolution_m:g} m"
    )
    print(f"wrote {paths['png']}, {paths['npy']}, {paths['json']}")
    if args.score:
        from sfw_gym.evaluation.logs import read_log_meta, score_map

        meta = read_log_meta(args.log)
        scores = score_map(result.occupancy_u8, result.grid, meta["truth_u8"], meta["truth_grid"])
        print("against the recorded truth: " + ", ".join(f"{k} {v:.3f}" for k, v in scores.items()))
    return 0
