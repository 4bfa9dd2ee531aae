"""Benchmark ``generate_floorplan``: time per plan over many seeds, and the plans' areas.

Usage:
    python scripts/benchmarks/bench_generator.py [--seeds 100] [--kind random|apartment|office]

Prints the median and 95th-percentile milliseconds per plan and the range of free areas.

Results: docs/results/speed.md#the-simulated-worlds-parts.
"""

from __future__ import annotations

import argparse
import collections
import platform
import time

import numpy as np

from sfw_gym.world.generator import generate_floorplan


def main(argv: list[str] | None = None) -> None:
    """Run the benchmark and print its figures."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=100, help="number of seeds (0..N-1)")
    parser.add_argument("--kind", default="random", choices=["random", "apartment", "office"])
    args = parser.parse_args(argv)

    generate_floorplan(0, kind=args.kind)  # warm-up (imports, shapely/GEOS first use)
    times, areas, rooms, kinds = [], [], [], collections.Counter()
    for seed in range(args.seeds):
        t0 = time.perf_counter()
        fp = generate_floorplan(seed, kind=args.kind)
        times.append(time.perf_counter() - t0)
        areas.append(fp.area_m2)
        rooms.append(len(fp.rooms))
        kinds[fp.name.split("-")[1]] += 1
    ms = 1e3 * np.asarray(times)
    print(f"generate_floorplan over {args.seeds} seeds (kind={args.kind}) on {platform.node()}:")
    med, p95 = np.median(ms), np.percentile(ms, 95)
    print(f"  median {med:.2f} ms, p95 {p95:.2f} ms, max {ms.max():.2f} ms")
    print(f"  free area {min(areas):.1f}–{max(areas):.1f} m² (median {np.median(areas):.1f})")
    print(f"  rooms per plan {min(rooms)}–{max(rooms)}; kinds {dict(kinds)}")


if __name__ == "__main__":
    main()
