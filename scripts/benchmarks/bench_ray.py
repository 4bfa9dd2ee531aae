"""Evaluation throughput against Ray workers (issue 17), and an estimate for a large cluster.

    python scripts/benchmarks/bench_ray.py [--plans 12] [--env SfW-Explore-v0]
        [--nodes 100 --cores 16]

Needs ``pip install 'sfw-gym[ray]'``. One workload (frontier and random on ``--plans`` plans,
whole episodes) run side by side: the local backend with 1 and 2 workers, the Ray backend with
1 and 2 workers (each Ray run starts and stops its own local Ray, which is counted). Prints
episodes per second, the speed-up over local with 1 worker, Ray's start-up, and the driver's
cost per record (the checkpoint append, the only per-episode work not spread over the workers).

The cluster estimate assumes: episodes independent and CPU-bound (no shared data: plans are
generated from seeds); one worker per core; the per-core rate of the 1-worker Ray run; the
parallel efficiency of this machine's 2-worker run (pessimistic: here the driver shares the 2
cores); and a ceiling of one record per driver cost. It is an estimate, not a measurement.

Results: docs/results/speed.md#scale-out-on-ray.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from sfw_gym.evaluation import evaluate
from sfw_gym.evaluation.checkpoint import append_record

AGENTS = ["frontier", "random"]


def timed_run(out: Path, plans: int, env_id: str, workers: int, backend: str) -> float:
    start = time.perf_counter()
    evaluate(
        AGENTS, plans, 7, out=out, workers=workers, env_id=env_id, progress=False, backend=backend
    )
    return time.perf_counter() - start


def ray_start_s() -> float:
    import ray

    start = time.perf_counter()
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    ray.shutdown()
    return time.perf_counter() - start


def driver_cost_s(folder: Path, records: int = 200) -> float:
    record = {"key": "frontier/plan-0/seed-7", "coverage": 0.8, **{f"f{i}": 1.0 for i in range(30)}}
    path = folder / "append.jsonl"
    start = time.perf_counter()
    for _ in range(records):
        append_record(path, record)
    return (time.perf_counter() - start) / records


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--plans", type=int, default=12)
    p.add_argument("--env", default="SfW-Explore-v0")
    p.add_argument("--nodes", type=int, default=100)
    p.add_argument("--cores", type=int, default=16, help="cores per node")
    p.add_argument("--study", type=int, default=16_000, help="episodes of the study to time")
    args = p.parse_args()
    episodes = len(AGENTS) * args.plans
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for backend, workers in (("local", 1), ("local", 2), ("ray", 1), ("ray", 2)):
            wall = timed_run(
                Path(tmp) / f"{backend}{workers}", args.plans, args.env, workers, backend
            )
            rows.append((backend, workers, wall, episodes / wall))
        start = ray_start_s()
        driver = driver_cost_s(Path(tmp))
    base = rows[0][3]
    print(f"{episodes} episodes ({', '.join(AGENTS)} on {args.plans} plans of {args.env})\n")
    print("| backend | workers | wall (s) | episodes/s | vs local, 1 worker |")
    print("|---|---:|---:|---:|---:|")
    for backend, workers, wall, rate in rows:
        print(f"| {backend} | {workers} | {wall:.1f} | {rate:.3f} | {rate / base:.2f}× |")
    ray1, ray2 = rows[2][3], rows[3][3]
    efficiency = ray2 / (2 * ray1)
    cores = args.nodes * args.cores
    ceiling = 1.0 / driver
    cluster = min(cores * ray1 * efficiency, ceiling)
    print(
        f"\nRay start-up (init + shutdown): {start:.1f} s; driver cost per record: "
        f"{driver * 1e3:.2f} ms (ceiling {ceiling:,.0f} episodes/s)"
    )
    print(f"2-worker efficiency here: {efficiency:.2f}")
    print(
        f"Estimate for {args.nodes} nodes × {args.cores} cores: {cluster:,.0f} episodes/s; "
        f"a {args.study:,}-episode study in {args.study / cluster / 60:.1f} min "
        f"(here, 2 Ray workers: {args.study / ray2 / 3600:.1f} h)"
    )


if __name__ == "__main__":
    main()
