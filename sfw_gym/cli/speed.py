"""``sfw-gym speed`` (alias ``bench``): the env's throughput, steps/s and reset ms beside
CartPole-v1, and optionally agents' episode times and memory."""

from __future__ import annotations

import argparse

from sfw_gym.cli.options import add_env, agents_from_here, non_negative_int, positive_int

EXAMPLE = "sfw-gym speed --steps 5000 --resets 50"
HELP = "the env's throughput: steps/s and reset ms beside CartPole-v1 (alias: bench)"
ALIASES = ["bench"]


def add_options(parser: argparse.ArgumentParser) -> None:
    add_env(parser)
    parser.add_argument("--steps", type=positive_int, default=5000, help="random steps to time")
    parser.add_argument("--resets", type=positive_int, default=50, help="resets to time")
    parser.add_argument(
        "--memory-steps",
        type=non_negative_int,
        default=0,
        help="also report RSS before/after this many steps (e.g. 100000)",
    )
    parser.add_argument(
        "--agents",
        default="",
        help="also time these agents' episodes beside random actions (e.g. frontier,regions-ppo), "
        "candidate_goals, and episode time by length",
    )
    parser.add_argument(
        "--agent-episodes", type=positive_int, default=3, help="seeds per env for --agents"
    )


def run(args: argparse.Namespace) -> int:
    from sfw_gym.bench import main_bench

    agents_from_here()
    agents = [a for a in args.agents.split(",") if a] if args.agents else None
    return main_bench(
        args.env, args.steps, args.resets, args.memory_steps, agents, args.agent_episodes
    )
