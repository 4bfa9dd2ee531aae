"""Reset time against the number of a plan's vertices (issue 14: a 10,000-vertex plan's reset
within 10x a 100-vertex plan's).

    python scripts/benchmarks/bench_plan_size.py [--vertices 100,1000,10000] [--resets 3]

Each plan is a round 16 m hall whose wall is serrated (radius 8 m, every other vertex 5 cm
further out, so the outline keeps its vertices when simplified to 1 cm), written as a HouseExpo
file and reset on ``SfW-Explore-v0`` with ``options={"floorplan": path}``; the median of
``--resets`` resets after a warm-up, and the ratio to the smallest plan's.

Results: docs/results/speed.md#reset-time-and-memory.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

import gymnasium as gym
import numpy as np

import sfw_gym  # noqa: F401  (registration)
from sfw_gym.world import load_floorplan


def serrated_hall(n: int, path: Path) -> None:
    theta = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    radius = 8.0 + 0.05 * (np.arange(n) % 2)
    verts = np.column_stack([8.5 + radius * np.cos(theta), 8.5 + radius * np.sin(theta)])
    path.write_text(json.dumps({"id": f"serrated-{n}", "verts": verts.round(6).tolist()}))


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--vertices", default="100,1000,10000")
    p.add_argument("--resets", type=int, default=3)
    args = p.parse_args()
    env = gym.make("SfW-Explore-v0")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for n in (int(v) for v in args.vertices.split(",")):
            path = Path(tmp) / f"serrated_{n}.json"
            serrated_hall(n, path)
            kept = len(load_floorplan(path).edges)
            env.reset(seed=0, options={"floorplan": str(path)})  # warm-up
            times = []
            for seed in range(1, args.resets + 1):
                start = time.perf_counter()
                env.reset(seed=seed, options={"floorplan": str(path)})
                times.append(time.perf_counter() - start)
            rows.append((n, kept, 1e3 * float(np.median(times))))
    base = rows[0][2]
    print("| vertices | walls simulated | reset [ms] | ÷ smallest |")
    print("|---:|---:|---:|---:|")
    for n, kept, ms in rows:
        print(f"| {n:,} | {kept:,} | {ms:.0f} | {ms / base:.1f}× |")


if __name__ == "__main__":
    main()
