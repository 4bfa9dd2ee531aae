"""What a decision of a learned menu explorer costs on CPU, beside frontier's steps.

    python scripts/benchmarks/bench_goals_agent.py [--agent regions-ppo|goals-ppo] [--model PATH]
        [--seeds 3]

Runs the learned agent (``regions-ppo``: ``RegionsPPOAgent``, a region every 20 steps;
``goals-ppo``: ``PPOAgent``, candidate goals; the shipped model by default; the old names ``ppo``
and ``ppo-goals`` still work) on ``SfW-Explore-v0`` held-out seeds and times each decision's two
parts, the candidate menu (``menu_observation``) and the policy's choice, then the whole episode
per step beside ``FrontierAgent``'s on the same seeds (one process, side by side).

Results: docs/results/training.md#what-a-learned-decision-costs.
"""

from __future__ import annotations

import argparse
import time

import gymnasium as gym
import numpy as np

import sfw_gym  # noqa: F401  (registration)
from sfw_gym.agents import make_agent
from sfw_gym.agents import regions as region_agent
from sfw_gym.envs import goals
from sfw_gym.rl import agent as goal_agent


def timed(table: dict[str, list[float]], name: str, fn):
    def wrapper(*args, **kwargs):
        start = time.perf_counter()
        result = fn(*args, **kwargs)
        table[name].append(time.perf_counter() - start)
        return result

    return wrapper


def episode_seconds(agent, seed: int) -> tuple[float, int]:
    env = gym.make("SfW-Explore-v0")
    obs, _ = env.reset(seed=seed)
    agent.reset(env, seed=seed)
    start, steps, done = time.perf_counter(), 0, False
    while not done:
        obs, _, terminated, truncated, _ = env.step(agent.act(obs))
        steps, done = steps + 1, terminated or truncated
    return time.perf_counter() - start, steps


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument(
        "--agent", choices=("regions-ppo", "goals-ppo", "ppo", "ppo-goals"), default="regions-ppo"
    )
    p.add_argument("--model", default=None, help="a trained folder (default: the shipped one)")
    p.add_argument("--seeds", type=int, default=3)
    args = p.parse_args()
    parts: dict[str, list[float]] = {"menu": [], "policy": []}
    menu = timed(parts, "menu", goals.menu_observation)
    goal_agent.menu_observation = region_agent.menu_observation = menu  # type: ignore[assignment]
    args.agent = {"ppo": "regions-ppo", "ppo-goals": "goals-ppo"}.get(args.agent, args.agent)
    learned = make_agent(args.agent, **({"path": args.model} if args.model else {}))
    choose = "_choose" if args.agent == "goals-ppo" else "choose"
    setattr(learned, choose, timed(parts, "policy", getattr(learned, choose)))
    frontier = make_agent("frontier")
    episode_seconds(learned, 0)  # warm-up: compiled kernels, torch
    episode_seconds(frontier, 0)
    for v in parts.values():
        v.clear()
    totals = {"ppo": [0.0, 0], "frontier": [0.0, 0]}
    for seed in range(2_000_000, 2_000_000 + args.seeds):
        for name, agent in (("ppo", learned), ("frontier", frontier)):
            t, n = episode_seconds(agent, seed)
            totals[name][0] += t
            totals[name][1] += n
    n_decisions = len(parts["policy"])
    print(f"{n_decisions} decisions over {args.seeds} episodes (SfW-Explore-v0, CPU):")
    for name, ts in parts.items():
        ms = 1e3 * np.asarray(ts)
        print(
            f"  {name:<7} {ms.mean():6.2f} ms per decision (median {np.median(ms):.2f}, p99 "
            f"{np.percentile(ms, 99):.2f})"
        )
    per_step = {name: 1e3 * t / n for name, (t, n) in totals.items()}
    for name, ms in per_step.items():
        print(f"  {name:<9} episode {ms:.2f} ms per step ({totals[name][1]} steps)")
    print(f"  ppo ÷ frontier per step: {per_step['ppo'] / per_step['frontier']:.2f}")


if __name__ == "__main__":
    main()
