"""Radio SLAM on drifting frontier runs: ATE of odometry vs ``radio_slam`` (issue 15, first look).

    python scripts/bench_radio_slam.py [--seeds 10] [--aps 16] [--steps 1500]

``SfW-Explore-v0`` with odometry noise (0.05 translation, 0.02 rad heading per step, relative),
``--aps`` background access points, the frontier agent for ``--steps`` steps on held-out seeds
2,000,000+; prints the ATE of odometry and of Radio SLAM per run and paired (mean, 95 % CI), and
how many closures were used and how many of them joined poses truly within 2 m.
"""

from __future__ import annotations

import argparse
import time

import gymnasium as gym
import numpy as np
from scipy import stats

import sfw_gym  # noqa: F401  (registration)
from sfw_gym.agents import FrontierAgent
from sfw_gym.slam import absolute_trajectory_error, radio_slam

NOISY = {"odometry_translation_std": 0.05, "odometry_heading_std_rad": 0.02}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--seeds", type=int, default=10)
    p.add_argument("--aps", type=int, default=16)
    p.add_argument("--steps", type=int, default=1500)
    args = p.parse_args()
    rows = []
    for seed in range(2_000_000, 2_000_000 + args.seeds):
        env = gym.make(
            "SfW-Explore-v0", n_background_aps=args.aps, robot=NOISY, max_steps=args.steps
        )
        obs, _ = env.reset(seed=seed)
        agent = FrontierAgent()
        agent.reset(env, seed=seed)
        truth, odometry, prints, done = [], [], [], False
        while not done:
            obs, _, terminated, truncated, info = env.step(agent.act(obs))
            truth.append(info["true_pose"])
            odometry.append(info["odometry_pose"])
            prints.append(info["fingerprint"])
            done = terminated or truncated
        t, o = np.array(truth), np.array(odometry)
        start = time.perf_counter()
        result = radio_slam(o, np.array(prints))
        wall = time.perf_counter() - start
        c = result.closures
        real = (
            np.mean(np.linalg.norm(t[c[:, 0], :2] - t[c[:, 1], :2], axis=1) < 2.0) if len(c) else 0
        )
        rows.append((absolute_trajectory_error(o, t), absolute_trajectory_error(result.poses, t)))
        print(
            f"seed {seed}: ATE odometry {rows[-1][0]:.2f} m, radio SLAM {rows[-1][1]:.2f} m; "
            f"{len(c)} closures, {real:.0%} within 2 m; {wall:.2f} s"
        )
    a = np.array(rows)
    diff = a[:, 1] - a[:, 0]
    half = stats.t.ppf(0.975, len(diff) - 1) * diff.std(ddof=1) / np.sqrt(len(diff))
    lo, hi = diff.mean() - half, diff.mean() + half
    print(
        f"mean ATE: odometry {a[:, 0].mean():.2f} m, radio SLAM {a[:, 1].mean():.2f} m; "
        f"paired difference {diff.mean():+.2f} [{lo:+.2f}, {hi:+.2f}] m"
    )


if __name__ == "__main__":
    main()
