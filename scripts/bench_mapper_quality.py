"""Map quality of sparse inverse k-visibility on real and generated floorplans (issue 3).

For every plan (the HouseExpo files in ``../shared/floorplans/houseexpo/`` and generated plans):
two routers placed by `place_routers`, a dense lawnmower survey of the free space (passes
``--spacing`` apart, a sample every 5 cm, keeping the robot's clearance), RSSI from `RadioModel`
(noise off, or the default noise), and the mapper fed sample by sample. Prints per plan and in
aggregate: the paper's IoU, free-space IoU, wall precision and interior-wall recall (2-cell
tolerance), k-value accuracy, coverage.

Usage:
    python scripts/bench_mapper_quality.py --noise off            # every plan, noise off
    python scripts/bench_mapper_quality.py --noise default --table  # estimators × policies
"""

from __future__ import annotations

import argparse
import math
import statistics
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import shapely

from sfw_gym.mapping import GridSpec, MapperConfig, SparseInverseKVisibility
from sfw_gym.metrics import evaluate_map
from sfw_gym.world import (
    Floorplan,
    RadioConfig,
    RadioModel,
    generate_floorplan,
    load_floorplan,
    place_routers,
)

HOUSEEXPO = Path(__file__).resolve().parents[2] / "shared" / "floorplans" / "houseexpo"
ROBOT_RADIUS_M = 0.17
METRICS = ("paper_iou", "free_iou", "wall_precision", "interior_wall_recall", "k_accuracy",
           "coverage")  # fmt: skip
TARGETS = {"paper_iou": 0.95, "free_iou": 0.85, "wall_precision": 0.8, "interior_wall_recall": 0.7}


@dataclass(frozen=True)
class Case:
    """One plan with one mapper configuration."""

    source: str  # a HouseExpo path or "gen:<seed>"
    noise: str  # "off" or "default"
    k_estimator: str
    router_policy: str
    resolution_m: float
    spacing_m: float


def lawnmower(plan: Floorplan, spacing_m: float, step_m: float = 0.05) -> np.ndarray:
    """Boustrophedon survey points (N, 2) with the robot's clearance from every wall."""
    region = plan.free_space.buffer(-(ROBOT_RADIUS_M + 0.02))
    xmin, ymin, xmax, ymax = plan.bounds
    xs = np.arange(xmin, xmax, step_m)
    rows = []
    for i, y in enumerate(np.arange(ymin + spacing_m / 2, ymax, spacing_m)):
        inside = shapely.contains_xy(region, xs, np.full_like(xs, y))
        pts = np.stack([xs[inside], np.full(inside.sum(), y)], axis=1)
        rows.append(pts if i % 2 == 0 else pts[::-1])
    return np.vstack(rows)


def load(source: str) -> Floorplan:
    if source.startswith("gen:"):
        return generate_floorplan(int(source[4:]))
    return load_floorplan(source)


def run_case(case: Case) -> dict[str, float | str]:
    plan = load(case.source)
    rng = np.random.default_rng(0)
    routers = place_routers(plan, 2, rng)
    radio_cfg = RadioConfig() if case.noise == "default" else RadioConfig().noiseless()
    radio = RadioModel(plan, routers, radio_cfg, rng)
    truth, origin = plan.rasterize(case.resolution_m)
    grid = GridSpec(origin, case.resolution_m, truth.shape)
    cfg = MapperConfig(k_estimator=case.k_estimator, router_policy=case.router_policy)
    mapper = SparseInverseKVisibility(grid, routers, cfg)
    pts = lawnmower(plan, case.spacing_m)
    true_k = radio.true_k(pts)
    correct = total = 0
    for p, k_true in zip(pts, true_k, strict=True):
        reading = radio.measure(p).astype(np.float64)
        mapper.update(p, reading)
        est = mapper.last_k
        ok = est >= 0
        correct += int((est[ok] == k_true[ok]).sum())
        total += int(ok.sum())
    result = evaluate_map(mapper.occupancy_u8, truth)
    result["k_accuracy"] = correct / total if total else math.nan
    return {"plan": plan.name[:12], "samples": len(pts), **result}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--noise", choices=["off", "default"], default="off")
    parser.add_argument("--generated", type=int, default=20, help="generated plans (seeds 0..N-1)")
    parser.add_argument("--resolution", type=float, default=0.1)
    parser.add_argument("--spacing", type=float, default=0.5, help="lawnmower pass spacing, m")
    parser.add_argument("--table", action="store_true",
                        help="all four estimator × policy combinations (aggregates only)")  # fmt: skip
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    sources = [str(p) for p in sorted(HOUSEEXPO.glob("*.json"))]
    sources += [f"gen:{s}" for s in range(args.generated)]
    combos = [("distance_aware", "strongest")]
    if args.table:
        combos = [(e, p) for e in ("kmeans", "distance_aware") for p in ("strongest", "all")]
    with ProcessPoolExecutor(args.workers) as pool:
        for estimator, policy in combos:
            cases = [Case(s, args.noise, estimator, policy, args.resolution, args.spacing)
                     for s in sources]  # fmt: skip
            results = list(pool.map(run_case, cases))
            print(f"\n## noise={args.noise}, k_estimator={estimator}, router_policy={policy}, "
                  f"{args.resolution} m cells, {args.spacing} m lawnmower")  # fmt: skip
            if not args.table:
                print("| plan | samples | " + " | ".join(METRICS) + " |")
                print("|---" * (len(METRICS) + 2) + "|")
                for r in results:
                    cells = " | ".join(f"{r[m]:.3f}" for m in METRICS)
                    print(f"| {r['plan']} | {r['samples']} | {cells} |")
            print("| aggregate | " + " | ".join(METRICS) + " |")
            print("|---" * (len(METRICS) + 1) + "|")
            for name, agg in (("mean", statistics.fmean), ("min", min)):
                cells = " | ".join(f"{agg(float(r[m]) for r in results):.3f}" for m in METRICS)
                print(f"| {name} | {cells} |")
            fails = [(r["plan"], m) for r in results for m, t in TARGETS.items() if r[m] < t]
            print(f"plans below a target {TARGETS}: {fails if fails else 'none'}")


if __name__ == "__main__":
    main()
