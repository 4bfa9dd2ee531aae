"""The region explorer's learning curve, with frontier's and the tuned heuristics' levels as lines.

    python scripts/figures/plot_regions_curve.py RUN [--episodes 4]

RUN is a ``sfw-gym train ppo_mask --env SfW-ExploreRegions-v0`` output folder. Each reference
agent drives ``SfW-Explore-v0`` (the run's env kwargs, without the privileged entry) on held-out
seeds (the run's seed + 1,000,000 + i); its episode is scored with the regions env's reward
(bits gained − cost per metre and per step, + the bonus at the coverage target, ÷ the scale),
so that its level is the return a region policy would have had by driving the same way. The
mean returns are drawn over RUN/training_curve.png and printed.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import gymnasium as gym
import numpy as np
import yaml

import sfw_gym  # noqa: F401  (registration)
from sfw_gym.agents import make_agent
from sfw_gym.envs.regions import RegionsConfig
from sfw_gym.rl.training import HELD_OUT_SEED_OFFSET, plot_training_curve

REFERENCES = {
    "frontier": ("frontier", {}),
    "frontier (potential_scale=1)": ("frontier", {"potential_scale": 1.0}),
    "greedy (distance_offset_m=0.3)": ("greedy", {"distance_offset_m": 0.3}),
}


def regions_return(agent_name: str, params: dict, seed: int, env_kwargs: dict) -> float:
    """One episode of the agent on the explore env, scored as the regions env scores it."""
    kwargs = {k: v for k, v in env_kwargs.items() if k not in ("regions", "privileged")}
    cfg = RegionsConfig.from_dict(env_kwargs.get("regions"), "regions")
    env = gym.make("SfW-Explore-v0", **kwargs)
    obs, info = env.reset(seed=seed)
    agent = make_agent(agent_name, **params)
    agent.reset(env, seed=seed)
    start_bits, steps, done = info["entropy_bits"], 0, False
    while not done:
        obs, _, terminated, truncated, info = env.step(agent.act(obs))
        steps += 1
        done = terminated or truncated
    bits = start_bits - info["entropy_bits"]
    bits -= cfg.cost_per_m_bits * info["path_length_m"] + cfg.cost_per_step_bits * steps
    bits += cfg.goal_bonus_bits * terminated
    return bits / cfg.reward_scale_bits


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("run", type=Path)
    p.add_argument("--episodes", type=int, default=4)
    args = p.parse_args()
    config = yaml.safe_load((args.run / "config.yml").read_text(encoding="utf-8"))
    seed = int(config.get("seed", 0)) + HELD_OUT_SEED_OFFSET
    env_kwargs = config.get("env_kwargs") or {}
    levels = {}
    for label, (name, params) in REFERENCES.items():
        returns = [regions_return(name, params, seed + i, env_kwargs) for i in range(args.episodes)]
        levels[f"{label}, {args.episodes} episodes"] = float(np.mean(returns))
    for name, level in levels.items():
        print(f"{name}: mean return {level:.2f}")
    print(plot_training_curve(args.run, levels=levels))


if __name__ == "__main__":
    main()
