"""Time the Radio SLAM pose graph (issue 15: 2,000 poses with their closures in <= 1 s).

    python scripts/benchmarks/bench_pose_graph.py [--poses 2000] [--laps 5] [--closure-m 1.5]
        [--every 1]

A walk of ``--laps`` laps around a 50 m x 30 m ellipse with drifting odometry (1 % scale noise,
0.003 rad heading bias per step); range closures between poses of different laps within
``--closure-m`` (the true distance, sigma 0.3 m; ``--every k`` keeps every k-th), found with a
KD-tree. Prints the optimisation time and the ATE before and after.

Results: docs/results/slam.md#radio-slam-in-the-simulated-env.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
from scipy.spatial import cKDTree

from sfw_gym.slam import PoseGraph, absolute_trajectory_error, compose_pose, relative_pose


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--poses", type=int, default=2000)
    p.add_argument("--laps", type=int, default=5)
    p.add_argument("--closure-m", type=float, default=1.5)
    p.add_argument("--every", type=int, default=1)
    args = p.parse_args()
    rng = np.random.default_rng(0)
    per_lap = args.poses // args.laps
    t = np.linspace(0, 2 * math.pi, per_lap, endpoint=False)
    lap = np.column_stack([25 + 25 * np.cos(t), 15 + 15 * np.sin(t), t + math.pi / 2])
    truth = np.concatenate([lap] * args.laps)
    graph = PoseGraph(len(truth))
    odometry = [truth[0]]
    for k in range(len(truth) - 1):
        dx, dy, dth = relative_pose(truth[k], truth[k + 1])
        measured = (dx * (1 + 0.01 * rng.normal()), dy, dth + 0.003 + 0.002 * rng.normal())
        graph.add_odometry(k, k + 1, measured, 0.05, 0.01)
        odometry.append(compose_pose(odometry[-1], measured))
    odometry_arr = np.array(odometry)
    pairs = sorted(cKDTree(truth[:, :2]).query_pairs(args.closure_m))
    pairs = [(i, j) for i, j in pairs if abs(i - j) >= per_lap // 4][:: args.every]
    for i, j in pairs:
        graph.add_range(i, j, float(np.linalg.norm(truth[i, :2] - truth[j, :2])), 0.3)
    start = time.perf_counter()
    solved = graph.optimize(odometry_arr)
    wall = time.perf_counter() - start
    before = absolute_trajectory_error(odometry_arr, truth)
    after = absolute_trajectory_error(solved, truth)
    print(
        f"{len(truth)} poses, {len(pairs)} closures: optimised in {wall:.2f} s; "
        f"ATE {before:.2f} m (odometry) -> {after:.2f} m"
    )


if __name__ == "__main__":
    main()
