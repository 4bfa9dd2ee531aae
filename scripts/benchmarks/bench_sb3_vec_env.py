"""PPO training throughput (env steps/s of ``model.learn``) on SB3's SubprocVecEnv, today's
``sfw-gym train`` default, beside the native vector env through ``SB3VecEnv`` (issue 33).

    python scripts/benchmarks/bench_sb3_vec_env.py --env SfW-ExploreDiscrete-v0 --timesteps 4096

Results: docs/results/speed.md#training-and-evaluation-on-the-native-env.
"""

from __future__ import annotations

import argparse
import time

import gymnasium as gym
import torch

import sfw_gym  # noqa: F401  (registers the ids)


def steps_per_s(venv, timesteps: int, threads: int) -> float:
    from stable_baselines3 import PPO

    torch.set_num_threads(threads)

    model = PPO("MultiInputPolicy", venv, n_steps=256, batch_size=256, n_epochs=2, seed=0)
    model.learn(512)  # warm-up
    start = time.perf_counter()
    model.learn(timesteps, reset_num_timesteps=False)
    rate = timesteps / (time.perf_counter() - start)
    venv.close()
    return rate


def main() -> None:
    from stable_baselines3.common.env_util import make_vec_env
    from stable_baselines3.common.vec_env import SubprocVecEnv

    from sfw_gym.rl.vec_env import SB3VecEnv

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--env", default="SfW-ExploreDiscrete-v0")
    parser.add_argument("--timesteps", type=int, default=4096)
    args = parser.parse_args()
    qualified = f"sfw_gym:{args.env}"
    rows = [  # (name, the vec env, torch threads)
        ("SubprocVecEnv, 4 envs", lambda: make_vec_env(qualified, 4, vec_env_cls=SubprocVecEnv), 1),
        ("SB3VecEnv(native), 4 envs", lambda: SB3VecEnv(gym.make_vec(args.env, num_envs=4)), 1),
        ("SB3VecEnv(native), 16 envs", lambda: SB3VecEnv(gym.make_vec(args.env, num_envs=16)), 1),
        # no env worker needs the second core: torch may have it
        ("SB3VecEnv(native), 4 envs, 2 torch threads",
         lambda: SB3VecEnv(gym.make_vec(args.env, num_envs=4)), 2),
        ("SB3VecEnv(native), 16 envs, 2 torch threads",
         lambda: SB3VecEnv(gym.make_vec(args.env, num_envs=16)), 2),
    ]  # fmt: skip
    base = None
    for name, make, threads in rows:
        rate = steps_per_s(make(), args.timesteps, threads)
        base = base or rate
        print(f"{name:45s} {rate:8,.0f} env steps/s  {rate / base:5.2f}x")


if __name__ == "__main__":
    main()
