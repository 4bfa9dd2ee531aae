"""The simulated LiDAR's cost (issue 18): µs per scan, env steps/s with and without a scan per
step, and the LiDAR occupancy map's update per scan.

    python scripts/benchmarks/bench_lidar.py [--beams 360] [--steps 2000] [--rounds 3]

Scans are timed from 200 random free poses on a generated plan (seed 0), on the HouseExpo plan
with the most walls (``../shared/floorplans/houseexpo``) and on a 49,000-vertex serrated round
hall of radius 8 m seen from its centre (every wall within range: the worst case for the plan
size the simulation takes). The env loop is ``SfW-Explore-v0`` with random actions, alone and
with one scan per step at the true pose, in alternating rounds of ``--steps`` steps (each from
``reset(seed=0)``), so that the ratio compares like with like; the map update is
:meth:`~sfw_gym.mapping.lidar_map.LidarOccupancyMap.integrate` on the env's grid.

Results: docs/results/slam.md#radiolidar-slam.
"""

from __future__ import annotations

import argparse
import json
import math
import tempfile
import time
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

import sfw_gym  # noqa: F401  (registration)
from sfw_gym.mapping.lidar_map import LidarOccupancyMap
from sfw_gym.world import Floorplan, generate_floorplan, load_floorplan
from sfw_gym.world.lidar import Lidar, LidarConfig

HOUSEEXPO = Path(__file__).resolve().parents[3] / "shared" / "floorplans" / "houseexpo"


def free_poses(plan: Floorplan, n: int, rng: np.random.Generator) -> list[tuple[float, ...]]:
    xmin, ymin, xmax, ymax = plan.bounds
    poses: list[tuple[float, ...]] = []
    while len(poses) < n:
        x, y = rng.uniform((xmin, ymin), (xmax, ymax))
        if plan.is_free(np.array([x, y])):
            poses.append((float(x), float(y), float(rng.uniform(-math.pi, math.pi))))
    return poses


def us_per_scan(lidar: Lidar, poses: list[tuple[float, ...]], repeat: int) -> float:
    rng = np.random.default_rng(0)
    for pose in poses:  # warm-up (compilation)
        lidar.scan(pose, rng)
    start = time.perf_counter()
    for _ in range(repeat):
        for pose in poses:
            lidar.scan(pose, rng)
    return 1e6 * (time.perf_counter() - start) / (repeat * len(poses))


def serrated_hall(n: int, path: Path) -> Floorplan:
    theta = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    radius = 8.0 + 0.05 * (np.arange(n) % 2)
    verts = np.column_stack([8.5 + radius * np.cos(theta), 8.5 + radius * np.sin(theta)])
    path.write_text(json.dumps({"id": f"serrated-{n}", "verts": verts.round(6).tolist()}))
    return load_floorplan(path)


def steps_per_s(env: gym.Env, steps: int, cfg: LidarConfig | None, seed: int) -> float:
    """Random-action steps per second, with a scan per step at the true pose given ``cfg``
    (the LiDAR built on each episode's plan at its reset)."""
    u: Any = env.unwrapped  # SfWExploreEnv
    rng = np.random.default_rng(seed)
    env.action_space.seed(seed)
    start = time.perf_counter()
    env.reset(seed=seed)
    lidar = None if cfg is None else Lidar(u.scene.floorplan, cfg)
    for _ in range(steps):
        _, _, terminated, truncated, _ = env.step(env.action_space.sample())
        if lidar is not None:
            lidar.scan(u.scene.robot.pose, rng)
        if terminated or truncated:
            env.reset()
            lidar = None if cfg is None else Lidar(u.scene.floorplan, cfg)
    return steps / (time.perf_counter() - start)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--beams", type=int, default=360)
    p.add_argument("--steps", type=int, default=2000)
    p.add_argument("--rounds", type=int, default=3)
    args = p.parse_args()
    cfg = LidarConfig(beams=args.beams)
    rng = np.random.default_rng(0)

    print(f"## Scan, {args.beams} beams, range {cfg.max_range_m:g} m\n")
    print("| plan | walls | µs per scan |")
    print("|---|---:|---:|")
    generated = generate_floorplan(0)
    plans: list[tuple[str, Floorplan, list[tuple[float, ...]], int]] = [
        ("generated (seed 0)", generated, free_poses(generated, 200, rng), 20)
    ]
    files = sorted(HOUSEEXPO.glob("*.json"))
    if files:
        house = max((load_floorplan(f) for f in files), key=lambda plan: len(plan.edges))
        plans.append((f"HouseExpo {house.name[:8]}", house, free_poses(house, 200, rng), 20))
    with tempfile.TemporaryDirectory() as tmp:
        hall = serrated_hall(49_000, Path(tmp) / "serrated.json")
    plans.append(("serrated hall, from its centre", hall, [(8.5, 8.5, 0.0)], 200))
    for name, plan, poses, repeat in plans:
        us = us_per_scan(Lidar(plan, cfg), poses, repeat)
        print(f"| {name} | {len(plan.edges):,} | {us:.1f} |")

    env = gym.make("SfW-Explore-v0")
    rates: dict[str, list[float]] = {"env alone": [], "env + 1 scan per step": []}
    steps_per_s(env, 200, cfg, 0)  # warm-up
    for _ in range(args.rounds):
        rates["env alone"].append(steps_per_s(env, args.steps, None, 0))
        rates["env + 1 scan per step"].append(steps_per_s(env, args.steps, cfg, 0))
    print(f"\n## SfW-Explore-v0, random actions, median of {args.rounds} rounds\n")
    print("| loop | steps/s |")
    print("|---|---:|")
    for name, values in rates.items():
        print(f"| {name} | {np.median(values):,.0f} |")
    ratio = np.median(rates["env + 1 scan per step"]) / np.median(rates["env alone"])
    print(f"\nwith a scan per step: {ratio:.2f}× the steps/s")

    u: Any = env.unwrapped  # SfWExploreEnv
    lidar = Lidar(u.scene.floorplan, cfg)
    poses = free_poses(u.scene.floorplan, 200, rng)
    scans = [lidar.scan(pose, rng) for pose in poses]
    occupancy = LidarOccupancyMap(u.grid)
    for pose, ranges in zip(poses, scans, strict=True):  # warm-up (compilation)
        occupancy.integrate(pose, lidar.angles, ranges, cfg.max_range_m)
    start = time.perf_counter()
    for pose, ranges in zip(poses, scans, strict=True):
        occupancy.integrate(pose, lidar.angles, ranges, cfg.max_range_m)
    us = 1e6 * (time.perf_counter() - start) / len(poses)
    rows, cols = u.grid.shape
    print(
        f"\n## LiDAR map: {us:.1f} µs per integrated scan "
        f"({rows} x {cols} cells of {u.grid.resolution_m:g} m)"
    )


if __name__ == "__main__":
    main()
