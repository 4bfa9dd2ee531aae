"""One env's steps/s as a fraction of CartPole-v1's, robust to a shared machine (issue 33).

The two envs are timed in alternating short rounds (random actions drawn beforehand, resets
included), and the figure is the median of the per-round ratios: a neighbour's load spike
slows both sides of a round alike instead of skewing one whole measurement.

    python scripts/benchmarks/bench_env_ratio.py --env SfW-Explore-v0 --rounds 21 --steps 400
    python scripts/benchmarks/bench_env_ratio.py --floorplan ../shared/floorplans/houseexpo/P.json
    python scripts/benchmarks/bench_env_ratio.py --rounds 21 --steps 400 --write-docs

Results: docs/results/speed.md#one-env-against-cartpole (the headline "× CartPole" figure).
``--write-docs`` writes the table, with the command, the date and the machine, between
``<!-- bench_env_ratio:begin -->`` and ``<!-- bench_env_ratio:end -->`` in that page.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

import gymnasium as gym
from _docs import RESULTS, command_line, machine, machine_short, write_block

import sfw_gym  # noqa: F401  (registers the ids)

DOC = RESULTS / "speed.md"
HEADLINE = "<!-- bench_env_ratio:headline -->"


def timed_steps(env: gym.Env, actions: list) -> float:
    """Seconds for ``actions`` (resetting at each episode's end)."""
    start = time.perf_counter()
    for action in actions:
        _, _, terminated, truncated, _ = env.step(action)
        if terminated or truncated:
            env.reset()
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--env", default="SfW-Explore-v0")
    parser.add_argument("--rounds", type=int, default=21)
    parser.add_argument("--steps", type=int, default=400, help="env steps per round")
    parser.add_argument("--floorplan", default=None, help="a plan file for every episode")
    parser.add_argument(
        "--write-docs",
        action="store_true",
        help="write the table into docs/results/speed.md (block bench_env_ratio)",
    )
    args = parser.parse_args()
    load_before = os.getloadavg()[0]
    kwargs = {} if args.floorplan is None else {"floorplan": args.floorplan}
    envs = {args.env: gym.make(args.env, **kwargs), "CartPole-v1": gym.make("CartPole-v1")}
    actions = {}
    for name, env in envs.items():
        env.reset(seed=0)
        env.action_space.seed(0)
        steps = args.steps if name == args.env else 20 * args.steps
        actions[name] = [env.action_space.sample() for _ in range(steps)]
        timed_steps(env, actions[name][:50])  # warm-up (compiled kernels, first-call checks)
    rates: dict[str, list[float]] = {name: [] for name in envs}
    for _ in range(args.rounds):
        for name, env in envs.items():
            rates[name].append(len(actions[name]) / timed_steps(env, actions[name]))
    ratios = [a / b for a, b in zip(rates[args.env], rates["CartPole-v1"], strict=True)]
    for name in envs:
        print(f"{name:24s} median {statistics.median(rates[name]):10,.0f} steps/s")
    q = statistics.quantiles(ratios, n=4)
    print(
        f"ratio {args.env} / CartPole-v1: median {statistics.median(ratios):.3f} "
        f"(quartiles {q[0]:.3f}-{q[2]:.3f}, {args.rounds} rounds of {args.steps} steps)"
    )
    if args.write_docs:
        write_block(DOC, "bench_env_ratio", docs_table(args, rates, ratios, q, load_before))


def docs_table(
    args: argparse.Namespace,
    rates: dict[str, list[float]],
    ratios: list[float],
    q: list[float],
    load_before: float,
) -> list[str]:
    """The generated block of docs/results/speed.md."""
    plan = f", every episode on `{args.floorplan}`" if args.floorplan else ", procedural plans"
    return [
        f"`{command_line()}`: {machine(load_before)}. Random actions through `gym.make`, "
        f"resets included{plan}; {args.rounds} alternating rounds of {args.steps:,} "
        f"{args.env} steps and {20 * args.steps:,} CartPole-v1 steps. Other jobs may share "
        "the cores: the ratio, taken round by round, is the figure to compare, not the steps/s.",
        "",
        "| env | steps/s, median over rounds |",
        "|---|---:|",
        *(f"| {name} | {statistics.median(r):,.0f} |" for name, r in rates.items()),
        "",
        HEADLINE,  # docs/results/index.md includes the line after it
        f"**{args.env} ÷ CartPole-v1: {statistics.median(ratios):.3f}×** (median of the "
        f"per-round ratios; quartiles {q[0]:.3f}–{q[2]:.3f}; {machine_short()}).",
    ]


if __name__ == "__main__":
    main()
