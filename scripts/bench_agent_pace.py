"""Agents at the env's pace (issue 39): per step, (act + env step) ÷ the random-action env step.

On the benchmark-v1 test split's first seeds and on HouseExpo plans, each agent's episode is timed
beside a random-action episode of the same plan and seed, interleaved, in one run; the table gives
the mean ratio of per-step times with a 95 % interval over episodes, and regions-ppo ÷ frontier.

    python scripts/bench_agent_pace.py --seeds 4 --plans 4
    python scripts/bench_agent_pace.py --agents frontier --seeds 2 --plans 0

Run it from another checkout (``PYTHONPATH=/path/to/checkout``) to get the "before" table.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import sfw_gym  # noqa: F401  (registers the ids)
from sfw_gym.bench import time_agent_episode
from sfw_gym.evaluation.benchmark import load_protocol, split_seeds

AGENTS = "frontier,cross-pass,greedy,region-teacher,regions-ppo"
HOUSEEXPO = Path(__file__).resolve().parents[1].parent / "shared" / "floorplans" / "houseexpo"


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
    args = parser.parse_args()
    agents = args.agents.split(",")
    first, _ = split_seeds(load_protocol(), "test")
    episodes: list[tuple[str, int, dict]] = [
        ("test split", first + i, {}) for i in range(args.seeds)
    ]
    plans = sorted(Path(args.houseexpo).glob("*.json"))[: args.plans]
    episodes += [("HouseExpo", 100 + i, {"floorplan": str(p)}) for i, p in enumerate(plans)]
    for agent in ["random", *agents]:  # warm-up: compiled kernels, model loads
        time_agent_episode(agent, args.env, 0, max_steps=50)
    per_step: dict[str, dict[str, list[float]]] = {}
    for where, seed, kwargs in episodes:
        row = per_step.setdefault(where, {a: [] for a in ["random", *agents]})
        for agent in row:
            seconds, steps = time_agent_episode(agent, args.env, seed, **kwargs)
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
    print(f"({args.env}; one episode per seed or plan, agents interleaved with random actions)")


if __name__ == "__main__":
    main()
