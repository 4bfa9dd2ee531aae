"""Agents at the env's pace (issue 39): per step, (act + env step) ÷ the random-action env step.

On the benchmark-v1 test split's first seeds and on HouseExpo plans, each agent's episode is timed
beside a random-action episode of the same plan and seed, interleaved, in one run; the table gives
the mean ratio of per-step times with a 95 % interval over episodes, and regions-ppo ÷ frontier.
``--clock cpu`` times the process's CPU seconds instead of wall seconds (PyTorch held to one
thread): on a machine shared with other jobs, a wall-clock ratio moves with their load.

    python scripts/benchmarks/bench_agent_pace.py --seeds 4 --plans 4
    python scripts/benchmarks/bench_agent_pace.py --agents frontier --seeds 2 --plans 0

Run it from another checkout (``PYTHONPATH=/path/to/checkout``) to get the "before" table: the
timing loop lives here, not in the package, so that it runs unchanged on older code.

Results: docs/results/agents.md#cost-per-step (the agents) and
docs/results/ceiling.md#what-the-oracles-cost (the oracles).
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable
from pathlib import Path

import gymnasium as gym
import numpy as np

import sfw_gym  # noqa: F401  (registers the ids)
from sfw_gym.agents import make_agent
from sfw_gym.evaluation.benchmark import load_protocol, split_seeds

AGENTS = "frontier,cross-pass,greedy,region-teacher,regions-ppo"
HOUSEEXPO = Path(__file__).resolve().parents[2].parent / "shared" / "floorplans" / "houseexpo"


CLOCKS: dict[str, Callable[[], float]] = {"wall": time.perf_counter, "cpu": time.process_time}


def time_episode(
    agent: str, env_id: str, seed: int, clock: Callable[[], float], **env_kwargs
) -> tuple[float, int]:
    """Seconds and steps of one episode of ``agent`` (``"random"``: sampled actions) on
    ``env_id`` reset with ``seed``: acting and stepping, not the env's construction or reset."""
    env = gym.make(env_id, **env_kwargs)
    obs, _ = env.reset(seed=seed)
    if agent == "random":
        env.action_space.seed(seed)
        act = lambda _obs: env.action_space.sample()  # noqa: E731
    else:
        a = make_agent(agent)
        a.reset(env, seed=seed)
        act = a.act
    steps, done = 0, False
    start = clock()
    while not done:
        obs, _, terminated, truncated, _ = env.step(act(obs))
        steps += 1
        done = terminated or truncated
    seconds = clock() - start
    env.close()
    return seconds, steps


def interval(ratios: np.ndarray) -> str:
    """``mean [lo, hi]`` with a normal 95 % interval."""
    half = 1.96 * ratios.std(ddof=1) / np.sqrt(len(ratios)) if len(ratios) > 1 else 0.0
    return f"{ratios.mean():.2f}x [{ratios.mean() - half:.2f}, {ratios.mean() + half:.2f}]"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--agents", default=AGENTS)
    parser.add_argument("--env", default="SfW-Explore-v0")
    parser.add_argument("--seeds", type=int, default=4, help="benchmark-v1 test seeds")
    parser.add_argument("--plans", type=int, default=4, help="HouseExpo plans (sorted by name)")
    parser.add_argument("--houseexpo", default=str(HOUSEEXPO))
    parser.add_argument("--clock", choices=sorted(CLOCKS), default="wall")
    args = parser.parse_args()
    clock = CLOCKS[args.clock]
    if args.clock == "cpu":
        try:
            import torch

            torch.set_num_threads(1)
        except ImportError:
            pass
    agents = args.agents.split(",")
    first, _ = split_seeds(load_protocol(), "test")
    episodes: list[tuple[str, int, dict]] = [
        ("test split", first + i, {}) for i in range(args.seeds)
    ]
    plans = sorted(Path(args.houseexpo).glob("*.json"))[: args.plans]
    episodes += [("HouseExpo", 100 + i, {"floorplan": str(p)}) for i, p in enumerate(plans)]
    for agent in ["random", *agents]:  # warm-up: compiled kernels, model loads
        time_episode(agent, args.env, 0, clock, max_steps=50)
    per_step: dict[str, dict[str, list[float]]] = {}
    for where, seed, kwargs in episodes:
        row = per_step.setdefault(where, {a: [] for a in ["random", *agents]})
        for agent in row:
            seconds, steps = time_episode(agent, args.env, seed, clock, **kwargs)
            row[agent].append(1e3 * seconds / steps)
        print(
            f"{where} seed {seed}: " + ", ".join(f"{a} {row[a][-1]:.3f}" for a in row), flush=True
        )
    print(f"\n{'set':<11} {'agent':<15} {'ms/step':>8}  (act + step) ÷ random step, 95 % CI")
    for where, row in per_step.items():
        base = np.array(row["random"])
        for agent, ms in row.items():
            ratio = np.array(ms) / base
            print(f"{where:<11} {agent:<15} {np.mean(ms):>8.3f}  {interval(ratio)}")
        if "regions-ppo" in row and "frontier" in row:
            ratio = np.array(row["regions-ppo"]) / np.array(row["frontier"])
            print(f"{where:<11} {'ppo ÷ frontier':<15} {'':>8}  {interval(ratio)}")
    print(
        f"({args.env}; {args.clock} clock; one episode per seed or plan, agents interleaved with "
        "random actions)"
    )


if __name__ == "__main__":
    main()
