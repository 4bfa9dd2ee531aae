"""Env steps/s of N SfW envs: the native vector env (``gym.make_vec``'s default) beside
Gymnasium's ``SyncVectorEnv`` and ``AsyncVectorEnv``, each as a multiple of one env's steps/s
measured in the same run (issue 33).

    python scripts/bench_vector_envs.py --env SfW-Explore-v0 --num-envs 16 --steps 200
"""

from __future__ import annotations

import argparse
import time

import gymnasium as gym

import sfw_gym  # noqa: F401  (registers the ids)


def env_steps_per_s(env: gym.Env | gym.vector.VectorEnv, steps: int, batch: int) -> float:
    """Env steps per second over ``steps`` calls of random actions (after a warm-up)."""
    env.reset(seed=0)
    env.action_space.seed(0)
    actions = [env.action_space.sample() for _ in range(steps + 20)]
    for action in actions[:20]:
        env.step(action)
    start = time.perf_counter()
    for action in actions[20:]:
        out = env.step(action)
        if batch == 1 and (out[2] or out[3]):
            env.reset()
    rate = steps * batch / (time.perf_counter() - start)
    env.close()
    return rate


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--env", default="SfW-Explore-v0")
    parser.add_argument("--num-envs", type=int, default=16)
    parser.add_argument("--steps", type=int, default=200, help="vector steps per measurement")
    args = parser.parse_args()
    n = args.num_envs
    env_steps_per_s(gym.make(args.env), 200, 1)  # warm-up: compiled kernels, first resets
    one = env_steps_per_s(gym.make(args.env), args.steps, 1)  # as far into its episode as each
    rows = [("one env", one)]
    for mode in ("vector_entry_point", "sync"):
        vec = gym.make_vec(args.env, num_envs=n, vectorization_mode=mode)
        rows.append((f"{n} envs, {mode}", env_steps_per_s(vec, args.steps, n)))
    vec = gym.make_vec(args.env, num_envs=2, vectorization_mode="async")
    rows.append(("2 envs, async (2 processes)", env_steps_per_s(vec, args.steps * 2, 2)))
    print(f"{args.env}: env steps/s, and as a multiple of one env's in this run")
    for name, rate in rows:
        print(f"  {name:34s} {rate:10,.0f}  {rate / one:5.2f}x")


if __name__ == "__main__":
    main()
