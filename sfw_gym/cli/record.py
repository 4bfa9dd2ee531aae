"""``sfw-gym record``: record an RSSI log (CSV, the SfW layout) from the simulator, with the
truth beside it."""

from __future__ import annotations

import argparse

from sfw_gym.cli.options import add_routers, add_seed, optional_routers, positive_float

EXAMPLE = "sfw-gym record walk.csv --seed 3 --routers 2"
HELP = "record an RSSI log (CSV, the SfW layout) from the simulator, the truth beside it"


def add_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("out", help="the CSV to write; .truth.npy and .truth.json go beside it")
    parser.add_argument("--floorplan", help="a floorplan file (default: a generated one)")
    add_seed(parser, "plan, routers, walk and radio")
    add_routers(parser)
    parser.add_argument(
        "--trajectory",
        choices=["walk", "survey"],
        default="walk",
        help="a person's walk from place to place, or a survey (walls, then 0.5 m passes)",
    )
    parser.add_argument("--step", type=positive_float, default=0.05, help="metres between samples")


def run(args: argparse.Namespace) -> int:
    from sfw_gym.evaluation.logs import read_log_meta, record_log
    from sfw_gym.world import generate_floorplan, load_floorplan
    from sfw_gym.world.floorplan import chosen_routers

    plan = load_floorplan(args.floorplan) if args.floorplan else generate_floorplan(args.seed)
    routers = chosen_routers(optional_routers(args.routers), plan, default=2)
    paths = record_log(
        plan, args.out, routers=routers, seed=args.seed, trajectory=args.trajectory,
        step_m=args.step,
    )  # fmt: skip
    meta = read_log_meta(paths["csv"])
    where = ";".join(f"{x:g},{y:g}" for x, y in meta["routers_px"])
    print(
        f"{plan.name}: {meta['samples']} samples ({args.trajectory}), "
        f"{len(meta['routers_px'])} router(s) at pixels {where}"
    )
    print(f"wrote {paths['csv']}, {paths['truth']}, {paths['json']}")
    print(
        f"map and score it: sfw-gym map {paths['csv']} --routers '{where}' "
        f"--px-per-m {1 / meta['pixel_m']:g} --y-down --score"
    )
    return 0
