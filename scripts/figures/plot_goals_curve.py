"""The candidate-goal explorer's learning curve, with the frontier's and greedy's level as lines.

    python scripts/figures/plot_goals_curve.py RUN [--episodes 6]

RUN is a ``sfw-gym train ppo_mask --env SfW-ExploreGoals-v0`` output folder. The two reference
policies choose on the same menu of ``SfW-ExploreGoals-v0`` as the learned one, on the held-out
episode stream of the run's evaluation (env seeded with the run's seed + 1,000,000, then
continued): explore_lite's utility (the frontier agent's choice, the behaviour-cloning teacher)
and greedy bits per metre (expected gain ÷ (path cost + 1 m), the greedy agent's score). Their
mean returns are drawn over RUN/training_curve.png and printed.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import gymnasium as gym
import numpy as np
import yaml

import sfw_gym  # noqa: F401  (registration)
from sfw_gym.agents.frontier import explore_lite_choice
from sfw_gym.agents.greedy import bits_per_metre
from sfw_gym.navigation.candidates import CandidateGoals
from sfw_gym.rl.training import HELD_OUT_SEED_OFFSET, plot_training_curve


def greedy_choice(menu: CandidateGoals) -> int | None:
    score = bits_per_metre(menu)
    return int(np.argmax(np.where(menu.valid, score, -np.inf))) if menu.valid.any() else None


def mean_return(choose, episodes: int, seed: int, env_kwargs: dict) -> float:
    env = gym.make("SfW-ExploreGoals-v0", **env_kwargs)
    returns = []
    for i in range(episodes):
        env.reset(seed=seed if i == 0 else None)
        total, done = 0.0, False
        while not done:
            choice = choose(env.unwrapped.menu)
            action = int(np.argmax(env.unwrapped.action_masks())) if choice is None else choice
            _, reward, terminated, truncated, _ = env.step(action)
            total += float(reward)
            done = terminated or truncated
        returns.append(total)
    return float(np.mean(returns))


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("run", type=Path)
    p.add_argument("--episodes", type=int, default=6)
    args = p.parse_args()
    config = yaml.safe_load((args.run / "config.yml").read_text(encoding="utf-8"))
    seed = int(config.get("seed", 0)) + HELD_OUT_SEED_OFFSET
    env_kwargs = config.get("env_kwargs") or {}
    levels = {
        f"frontier's choice (explore_lite), {args.episodes} episodes": mean_return(
            explore_lite_choice, args.episodes, seed, env_kwargs
        ),
        f"greedy bits per metre, {args.episodes} episodes": mean_return(
            greedy_choice, args.episodes, seed, env_kwargs
        ),
    }
    for name, level in levels.items():
        print(f"{name}: mean return {level:.2f}")
    print(plot_training_curve(args.run, levels=levels))


if __name__ == "__main__":
    main()
