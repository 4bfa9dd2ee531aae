"""The env's router policy, measured where the env uses it (issue 31): frontier episodes on an env
id with the mapper's ``router_policy`` "strongest" (the env's default) vs "all", paired on the
same seeds (the same plan, routers, radio and, up to the maps' influence on frontier, route).
Prints the final maps' free-space IoU, wall precision and interior-wall recall per policy and the
paired differences (all − strongest) with 95 % intervals (the package's paired comparison: a
seeded bootstrap over the seeds).

    python scripts/studies/env_router_policy.py --episodes 12 --seed 2000000
"""

from __future__ import annotations

import argparse
from concurrent.futures import ProcessPoolExecutor

import gymnasium as gym
import numpy as np

import sfw_gym  # noqa: F401  (registers the envs)
from sfw_gym.agents import make_agent
from sfw_gym.evaluation.stats import compare_paired
from sfw_gym.mapping.metrics import evaluate_map

METRICS = ("free_iou", "wall_precision", "interior_wall_recall")
POLICIES = ("strongest", "all")


def episode(job: tuple[str, int, str]) -> dict[str, float]:
    env_id, seed, policy = job
    env = gym.make(env_id, mapper={"router_policy": policy})
    obs, _ = env.reset(seed=seed)
    agent = make_agent("frontier")
    agent.reset(env, seed=seed)
    done = False
    while not done:
        obs, _, terminated, truncated, _ = env.step(agent.act(obs))
        done = terminated or truncated
    u = env.unwrapped
    scores = evaluate_map(u.mapper.occupancy_u8, u.scene.truth_u8)
    env.close()
    return {m: scores[m] for m in METRICS}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--env", default="SfW-Explore-v0")
    parser.add_argument("--episodes", type=int, default=12)
    parser.add_argument("--seed", type=int, default=2_000_000)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    seeds = range(args.seed, args.seed + args.episodes)
    jobs = [(args.env, s, p) for p in POLICIES for s in seeds]
    with ProcessPoolExecutor(args.workers) as pool:
        rows = list(pool.map(episode, jobs))
    by = {p: rows[i * args.episodes : (i + 1) * args.episodes] for i, p in enumerate(POLICIES)}
    print(f"{args.env}, frontier, {args.episodes} seeds from {args.seed}: mean (all − strongest)")
    print("| metric | strongest | all | all − strongest [95 % CI] |\n|---|---|---|---|")
    for m in METRICS:
        a, b = (np.array([r[m] for r in by[p]], float) for p in POLICIES)
        d = compare_paired(a, b)
        print(
            f"| {m} | {np.nanmean(a):.3f} | {np.nanmean(b):.3f} | {d.text('{:+.3f}')} (n={d.n}) |"
        )


if __name__ == "__main__":
    main()
