"""Map quality of sparse inverse k-visibility on real and generated floorplans (issue 3).

For every plan (the HouseExpo files in ``../shared/floorplans/houseexpo/`` and generated plans):
two routers placed by `place_routers`, a dense survey of the free space, RSSI from `RadioModel`
(noise off, or the default shadowing and noise), and the mapper fed sample by sample. Prints per
plan and in aggregate: the paper's IoU, free-space IoU, wall precision and interior-wall recall
(2-cell tolerance), k-value accuracy, coverage.

The survey is one continuous, physically valid path (a sample every 5 cm) inside the free space
shrunk by the robot's clearance (its 0.17 m radius + 2 cm): first a wall-following pass around
every boundary of that region, then a lawnmower (boustrophedon) of passes ``--spacing`` apart,
each pass continuing into an overlapping one of the next row where it can, with collision-free
transits (straight where possible, else a breadth-first path on a 5 cm grid, string-pulled)
in between. The robot never jumps, so the mapper never joins two samples through a wall.
``--survey lawnmower`` drops the wall-following pass.

The mapper is configured as the environment configures it: ``k0_level_dbm = P_tx - PL(1 m)``
(the robot knows its routers' transmit power; the free-space loss at 1 m is standard); rows
labelled ``distance_aware`` without ``+k0`` drop that calibration.

k-accuracy is the paper's Eq. 8 with true k counted up to ``max_k``: the estimator's top value
K means "K or more walls" (the paper's rule), so a reading of K where the truth is K or more is
right (``k_value_accuracy(..., max_k=K)``). ``k_exact`` compares with the uncapped truth.

Usage:
    python scripts/benchmarks/bench_mapper_quality.py --noise off             # every plan
    python scripts/benchmarks/bench_mapper_quality.py --noise default --table # estimator x policy
    python scripts/benchmarks/bench_mapper_quality.py --noise off --oracle    # + dense-oracle bound

Results: docs/results/mapping.md#map-quality-on-a-dense-survey.
"""

from __future__ import annotations

import argparse
import statistics
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from sfw_gym.mapping import (
    GridSpec,
    MapperConfig,
    SparseInverseKVisibility,
    dense_inverse_k_visibility,
)
from sfw_gym.mapping.metrics import evaluate_map, k_value_accuracy
from sfw_gym.world import (
    Floorplan,
    RadioConfig,
    RadioModel,
    generate_floorplan,
    load_floorplan,
    place_routers,
)
from sfw_gym.world.walks import CLEARANCE_M, survey

HOUSEEXPO = Path(__file__).resolve().parents[3] / "shared" / "floorplans" / "houseexpo"
ROBOT_RADIUS_M = 0.17
METRICS = (
    "paper_iou",
    "free_iou",
    "wall_precision",
    "interior_wall_recall",
    "k_accuracy",
    "k_exact",
    "coverage",
)
ORACLE_METRICS = ("oracle_free_iou", "oracle_wall_recall")
TARGETS = {"paper_iou": 0.95, "free_iou": 0.85, "wall_precision": 0.8, "interior_wall_recall": 0.7}


# -- one plan -------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Case:
    """One plan with every mapper configuration to run on it."""

    source: str  # a HouseExpo path or "gen:<seed>"
    noise: str  # "off" or "default"
    configs: tuple  # ((label, MapperConfig), ...)
    resolution_m: float
    spacing_m: float
    wall_follow: bool
    oracle: bool


def load(source: str) -> Floorplan:
    if source.startswith("gen:"):
        return generate_floorplan(int(source[4:]))
    return load_floorplan(source)


def oracle_map(radio: RadioModel, truth: np.ndarray, grid: GridSpec) -> np.ndarray:
    """Dense inverse k-visibility from the true k of every free cell (an upper bound)."""
    xs, ys = grid.cell_centres()
    k = radio.true_k(np.stack([xs.ravel(), ys.ravel()], axis=1)).T
    k = k.reshape(radio.n_routers, *grid.shape).astype(np.int64)
    k[:, truth != 255] = -1
    return dense_inverse_k_visibility(grid, radio.routers, k, adjacent_steps=False)


def run_case(case: Case) -> list[dict]:
    plan = load(case.source)
    rng = np.random.default_rng(0)
    routers = place_routers(plan, 2, rng)
    radio_cfg = RadioConfig() if case.noise == "default" else RadioConfig().noiseless()
    radio = RadioModel(plan, routers, radio_cfg, rng)
    truth, origin = plan.rasterize(case.resolution_m)
    grid = GridSpec(origin, case.resolution_m, truth.shape)
    pts = survey(plan, case.spacing_m, case.wall_follow)
    readings = np.empty((len(pts), len(routers)))
    true_k = np.empty((len(pts), len(routers)), np.int64)
    for i, p in enumerate(pts):  # one reading sequence, shared by every configuration
        readings[i], true_k[i] = radio.measure_with_k(p)
    name = plan.name if plan.name.startswith("gen") else plan.name[:12]
    extra = {}
    if case.oracle:
        o = evaluate_map(oracle_map(radio, truth, grid), truth)
        extra = {"oracle_free_iou": o["free_iou"], "oracle_wall_recall": o["interior_wall_recall"]}
    results = []
    for label, cfg in case.configs:
        mapper = SparseInverseKVisibility(grid, routers, cfg)
        k_est = np.empty_like(true_k)
        for i, p in enumerate(pts):
            mapper.update(p, readings[i])
            k_est[i] = mapper.last_k
        res = evaluate_map(mapper.occupancy_u8, truth)
        res["k_accuracy"] = k_value_accuracy(k_est, true_k, max_k=cfg.max_k)
        res["k_exact"] = k_value_accuracy(k_est, true_k)
        results.append({"config": label, "plan": name, "samples": len(pts), **res, **extra})
    return results


def configs_for(table: bool, k0_dbm: float) -> list[tuple[str, MapperConfig]]:
    """(label, config) pairs: the environment's configuration first, then the comparisons."""
    env = MapperConfig(robot_radius_m=ROBOT_RADIUS_M, k0_level_dbm=k0_dbm)
    no_k0 = replace(env, k0_level_dbm=None)
    kmeans = replace(no_k0, k_estimator="kmeans")
    if not table:
        return [("distance_aware+k0 / strongest", env), ("distance_aware / strongest", no_k0)]
    out = []
    for policy in ("strongest", "all"):
        for label, cfg in (
            ("kmeans", kmeans),
            ("distance_aware", no_k0),
            ("distance_aware+k0", env),
        ):
            out.append((f"{label} / {policy}", replace(cfg, router_policy=policy)))
    return out


def fmt(v: float) -> str:
    return "  nan" if v != v else f"{v:.3f}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--noise", choices=["off", "default"], default="off")
    parser.add_argument("--generated", type=int, default=20, help="generated plans (seeds 0..N-1)")
    parser.add_argument("--resolution", type=float, default=0.1)
    parser.add_argument("--spacing", type=float, default=0.5, help="lawnmower pass spacing, m")
    parser.add_argument(
        "--survey", choices=["wall+lawnmower", "lawnmower"], default="wall+lawnmower"
    )
    parser.add_argument(
        "--table", action="store_true", help="estimators x policies x calibration (aggregates only)"
    )
    parser.add_argument(
        "--oracle",
        action="store_true",
        help="also the dense oracle's free IoU, interior-wall recall",
    )
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    sources = [str(p) for p in sorted(HOUSEEXPO.glob("*.json"))]
    sources += [f"gen:{s}" for s in range(args.generated)]
    radio = RadioConfig()
    k0 = radio.tx_power_dbm - radio.d0_loss_db  # what the environment passes
    configs = configs_for(args.table, k0)
    cases = [
        Case(
            s,
            args.noise,
            tuple(configs),
            args.resolution,
            args.spacing,
            args.survey == "wall+lawnmower",
            args.oracle,
        )
        for s in sources
    ]
    with ProcessPoolExecutor(args.workers) as pool:
        per_plan = list(pool.map(run_case, cases))
    print(
        f"noise={args.noise}, {args.resolution} m cells, survey {args.survey} "
        f"({args.spacing} m passes, {CLEARANCE_M:.2f} m clearance), k0 = {k0:.1f} dBm, "
        f"{len(sources)} plans"
    )
    cols = METRICS + (ORACLE_METRICS if args.oracle else ())
    summary = []
    for c, (label, _) in enumerate(configs):
        results = [rs[c] for rs in per_plan]
        if not args.table and c == 0:
            print(f"\n## {label}\n")
            print("| plan | samples | " + " | ".join(cols) + " |")
            print("|---" * (len(cols) + 2) + "|")
            for r in results:
                print(
                    f"| {r['plan']} | {r['samples']} | "
                    + " | ".join(fmt(r[m]) for m in cols)
                    + " |"
                )
        fails = [
            (r["plan"], m, round(r[m], 3)) for r in results for m, t in TARGETS.items() if r[m] < t
        ]
        undefined = [(r["plan"], m) for r in results for m in TARGETS if r[m] != r[m]]
        summary.append((label, results, fails, undefined))
    print("\n## aggregate over plans (mean / min)\n")
    print("| configuration | " + " | ".join(cols) + " | plans below a target |")
    print("|---" * (len(cols) + 2) + "|")
    for label, results, fails, _ in summary:
        cells = []
        for m in cols:
            vals = [float(r[m]) for r in results if r[m] == r[m]]
            cells.append(f"{statistics.fmean(vals):.3f} / {min(vals):.3f}" if vals else "nan")
        print(f"| {label} | " + " | ".join(cells) + f" | {len({p for p, _, _ in fails})} |")
    print(f"\ntargets {TARGETS}")
    for label, _, fails, undefined in summary:
        print(
            f"{label}: below a target: {fails if fails else 'none'}"
            + (f"; undefined (nan): {undefined}" if undefined else "")
        )


if __name__ == "__main__":
    main()
