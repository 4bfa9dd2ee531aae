"""Benchmark the simulated world: wall counting, plan generation, RSSI.

Usage: python scripts/benchmarks/bench_world.py [--houseexpo DIR] [--seeds 100]
Prints segments/s of `count_walls`, median ms of `generate_floorplan`, points/s of `mean_rssi`,
and the agreement of `count_walls` with an independent shapely computation.

Results: docs/results/speed.md#the-simulated-worlds-parts.
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import numpy as np
from shapely.geometry import LineString

from sfw_gym.world import RadioConfig, RadioModel, generate_floorplan, load_floorplan, place_routers

DEFAULT_HOUSEEXPO = Path(__file__).resolve().parents[3] / "shared" / "floorplans" / "houseexpo"


def free_points(plan, n: int, rng: np.random.Generator) -> np.ndarray:
    xmin, ymin, xmax, ymax = plan.bounds
    pts = np.empty((0, 2))
    while len(pts) < n:
        cand = rng.uniform((xmin, ymin), (xmax, ymax), (2 * n, 2))
        pts = np.vstack([pts, cand[plan.is_free(cand)]])
    return pts[:n]


def shapely_pieces(plan, a, b, min_piece_m: float = 0.02) -> int:
    """Shapely count: pieces of the segment outside free space (≥ 2 cm, 2 cm gaps merged)."""
    seg = LineString([a, b])
    out = seg.difference(plan.free_space)
    spans = sorted(
        sorted((seg.project(g.interpolate(0)), seg.project(g.interpolate(1, normalized=True))))
        for g in getattr(out, "geoms", [out])
        if g.length >= min_piece_m
    )
    count, last = 0, -np.inf
    for start, end in spans:
        count += start - last >= min_piece_m
        last = max(last, end)
    return count


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--houseexpo", type=Path, default=DEFAULT_HOUSEEXPO)
    parser.add_argument("--seeds", type=int, default=100)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    plans = [load_floorplan(p) for p in sorted(args.houseexpo.glob("*.json"))]
    print(f"{len(plans)} HouseExpo plans from {args.houseexpo}")

    # count_walls: 100k segments between free points, per plan
    rates, agree, total = [], 0, 0
    for plan in plans:
        pts = free_points(plan, 200_000, rng)
        a, b = pts[:100_000], pts[100_000:]
        plan.count_walls(a[:5000], b[:5000])  # warm-up (the parallel kernel)
        start = time.perf_counter()
        k = plan.count_walls(a, b)
        rates.append(len(a) / (time.perf_counter() - start))
        ref = np.array([shapely_pieces(plan, a[i], b[i]) for i in range(1000)])
        agree += int((ref == k[:1000]).sum())
        total += 1000
    print(
        f"count_walls (all cores): median {statistics.median(rates) / 1e6:.2f} M segments/s "
        f"(min {min(rates) / 1e6:.2f}, max {max(rates) / 1e6:.2f}) over {len(plans)} plans"
    )
    print(f"count_walls vs shapely: {agree}/{total} = {100 * agree / total:.2f} % agree")
    plan = plans[0]
    a, b = free_points(plan, 2, rng)[None, 0], free_points(plan, 2, rng)[None, 1]
    start = time.perf_counter()
    for _ in range(20_000):
        plan.count_walls(a, b)
    per_call_us = (time.perf_counter() - start) / 20_000 * 1e6
    print(f"count_walls single segment (step path): {per_call_us:.1f} µs/call")

    # generate_floorplan
    generate_floorplan(0)
    times, areas = [], []
    for seed in range(args.seeds):
        start = time.perf_counter()
        g = generate_floorplan(seed)
        times.append((time.perf_counter() - start) * 1e3)
        areas.append(g.area_m2)
    print(
        f"generate_floorplan: median {statistics.median(times):.1f} ms, "
        f"p95 {np.percentile(times, 95):.1f} ms over {args.seeds} seeds; "
        f"area {min(areas):.0f}–{max(areas):.0f} m²"
    )

    # mean_rssi: 1e5 points x 4 routers
    plan = max(plans, key=lambda p: p.area_m2)
    radio = RadioModel(plan, place_routers(plan, 4, rng), RadioConfig(), rng)
    pts = rng.uniform(plan.bounds[:2], plan.bounds[2:], (100_000, 2))
    radio.mean_rssi(pts[:5000])  # warm-up (the parallel kernel)
    start = time.perf_counter()
    radio.mean_rssi(pts)
    took = time.perf_counter() - start
    print(
        f"mean_rssi: 1e5 points × 4 routers in {took * 1e3:.0f} ms = "
        f"{1e5 / took / 1e3:.0f} k points/s "
        f"({plan.name}, {plan.area_m2:.0f} m², {len(plan.edges)} wall faces)"
    )
    start = time.perf_counter()
    for _ in range(5000):
        radio.measure(pts[0])
    per_call_us = (time.perf_counter() - start) / 5000 * 1e6
    print(f"measure (one reading, 4 routers): {per_call_us:.1f} µs/call")


if __name__ == "__main__":
    main()
