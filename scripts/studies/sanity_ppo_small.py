"""The first rung of the learning sanity ladder: plain PPO on raw wheel commands beats random.

    python scripts/studies/sanity_ppo_small.py [--timesteps 40000] [--out runs/sanity_small]
    [--episodes 20]

Trains ``sfw-gym train ppo`` on ``SfW-ExploreSmall-v0`` (raw continuous actions, SB3's
``MultiInputPolicy``, the hyperparameters and ``env_kwargs`` of ``ppo.yml``; resumable), prints
the held-out return at each evaluation (the learning curve), then the episode return of the trained
policy and of uniformly random actions on the same held-out seeds (2,000,000 + i), paired: mean
difference with a 95 % interval (the package's paired comparison: a seeded bootstrap). If this
does not rise, nothing above it will.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import gymnasium as gym
import numpy as np

import sfw_gym  # noqa: F401  (registration)
from sfw_gym.evaluation.stats import compare_paired
from sfw_gym.rl.training import train_ppo

ENV_ID = "SfW-ExploreSmall-v0"


def episode_return(env: gym.Env, seed: int, act) -> float:
    obs, _ = env.reset(seed=seed)
    total, done = 0.0, False
    while not done:
        obs, reward, terminated, truncated, _ = env.step(act(obs))
        total, done = total + float(reward), terminated or truncated
    return total


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--timesteps", type=int, default=40_000)
    p.add_argument("--out", default="runs/sanity_small")
    p.add_argument("--episodes", type=int, default=20)
    args = p.parse_args()
    out = Path(args.out)
    summary = train_ppo(
        ENV_ID,
        args.timesteps,
        out,
        eval_every=max(args.timesteps // 8, 1),
        eval_episodes=10,
        checkpoint_every=max(args.timesteps // 4, 1),
        resume=True,
        progress_bar=False,
    )
    print(f"trained {summary['steps']} steps in {summary['total_wall_time_s']:.0f} s")
    evals = np.load(out / "eval" / "evaluations.npz")
    print("held-out return during training (mean over 10 episodes):")
    for step, returns in zip(evals["timesteps"], evals["results"], strict=True):
        print(f"  {int(step):>7} steps  {np.mean(returns):7.2f}")

    from stable_baselines3 import PPO

    model = PPO.load(out / f"{ENV_ID}.zip", device="cpu")
    env = gym.make(ENV_ID, **summary["env_kwargs"])  # as trained (the YAML's env_kwargs)
    env.action_space.seed(0)
    seeds = range(2_000_000, 2_000_000 + args.episodes)
    learned = [episode_return(env, s, lambda o: model.predict(o)[0]) for s in seeds]
    random = [episode_return(env, s, lambda o: env.action_space.sample()) for s in seeds]
    d = compare_paired(random, learned)
    print(
        f"{args.episodes} held-out seeds, episode return: PPO {np.mean(learned):.2f} (sampled "
        f"actions), random actions {np.mean(random):.2f}"
    )
    print(f"  PPO − random, paired: {d.text()}")


if __name__ == "__main__":
    main()
