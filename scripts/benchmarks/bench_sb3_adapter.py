"""SB3VecEnv's step on the native vector env (what PPO training steps), env steps per CPU second,
side by side with the code in another tree (issue 50: the step split into ``_step_once``).

    git worktree add /tmp/base 4645283
    python scripts/benchmarks/bench_sb3_adapter.py --rounds 7 --against /tmp/base

Each round times this checkout and the other tree in turn, each in a fresh process (the package
imported from ``PYTHONPATH``), on the same seeded random actions; printed: the per-round ratio
(this ÷ other), its median and quartiles.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys

import numpy as np

CHILD = """
import time, numpy as np, gymnasium as gym, sfw_gym
from sfw_gym.rl.vec_env import SB3VecEnv
venv = SB3VecEnv(gym.make_vec({env!r}, num_envs={n}))
venv.seed(0)
venv.reset()
actions = np.random.default_rng(0).uniform(-1, 1, ({steps} + 20, {n}, 2)).astype(np.float32)
for a in actions[:20]:
    venv.step(a)
start = time.process_time()
for a in actions[20:]:
    venv.step(a)
print({steps} * {n} / (time.process_time() - start))
"""


def rate(code: str, tree: str | None) -> float:
    env = {**os.environ, **({"PYTHONPATH": tree} if tree else {})}
    done = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True,
        cwd="/",
    )  # fmt: skip
    return float(done.stdout.split()[-1])


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--env", default="SfW-Explore-v0")
    p.add_argument("--num-envs", type=int, default=16)
    p.add_argument("--steps", type=int, default=1500, help="vector steps per measurement")
    p.add_argument("--rounds", type=int, default=9)
    p.add_argument("--against", required=True, help="the other tree (a worktree of a commit)")
    args = p.parse_args()
    code = CHILD.format(env=args.env, n=args.num_envs, steps=args.steps)
    rate(code, args.against)  # compiles the other tree's numba cache, untimed
    ours, theirs = [], []
    for _ in range(args.rounds):
        ours.append(rate(code, None))
        theirs.append(rate(code, args.against))
    ratios = np.array(ours) / np.array(theirs)
    q1, median, q3 = np.percentile(ratios, [25, 50, 75])
    print(f"| code | env steps per CPU second, median of {args.rounds} rounds |\n|---|---:|")
    print(
        f"| this checkout | {np.median(ours):,.0f} |\n| {args.against} | {np.median(theirs):,.0f} |"
    )
    print(
        f"this ÷ other: {median:.3f} (quartiles {q1:.3f}–{q3:.3f}; per round "
        f"{', '.join(f'{r:.3f}' for r in ratios)})"
    )


if __name__ == "__main__":
    main()
