"""``sfw-gym world``: draw a floorplan, its routers, RSSI and true k-regions."""

from __future__ import annotations

import argparse
import time

import numpy as np

from sfw_gym.cli.options import add_routers, add_seed, optional_routers, positive_float

EXAMPLE = "sfw-gym world --seed 3 --out world.png"
HELP = "draw a floorplan, its routers, RSSI and true k-regions"


def add_options(parser: argparse.ArgumentParser) -> None:
    from sfw_gym.world.radio import BANDS, PRESETS

    source = parser.add_mutually_exclusive_group()
    add_seed(source, "procedural floorplan seed")
    source.add_argument(
        "--floorplan", help="a floorplan file: HouseExpo or sfw_gym JSON, or a ROS map YAML"
    )
    add_routers(parser)
    parser.add_argument("--preset", choices=PRESETS, default="default", help="radio preset")
    parser.add_argument("--band", choices=list(BANDS), default="2.4", help="GHz")
    parser.add_argument(
        "--resolution", type=positive_float, default=0.1, help="heat-map cell size, metres"
    )
    parser.add_argument("--out", default="world.png", help="output PNG")


def run(args: argparse.Namespace) -> int:
    from sfw_gym.world import RadioConfig, RadioModel, load_floorplan, place_routers
    from sfw_gym.world.floorplan import chosen_routers
    from sfw_gym.world.picture import draw_world

    start = time.perf_counter()
    rng = np.random.default_rng(args.seed)
    if args.floorplan:
        plan = load_floorplan(args.floorplan)
    else:
        from sfw_gym.world.generator import generate_floorplan

        plan = generate_floorplan(args.seed)
    routers = chosen_routers(optional_routers(args.routers), plan, default=2)
    if isinstance(routers, int):
        routers = place_routers(plan, routers, rng)
    radio = RadioModel(plan, routers, RadioConfig.preset(args.preset, band=args.band), rng)
    out = draw_world(plan, radio, args.out, resolution_m=args.resolution)
    took = time.perf_counter() - start
    print(
        f"{plan.name}: {plan.area_m2:.1f} m², {len(plan.edges)} wall faces, routers at "
        f"{np.round(radio.routers, 2).tolist()}"
    )
    print(f"wrote {out} in {took:.1f} s")
    return 0
