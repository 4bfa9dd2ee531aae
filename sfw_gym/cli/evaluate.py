"""``sfw-gym evaluate``: compare agents on the same floorplans and seeds (a table, curves,
paths, and each agent's paired differences from the first)."""

from __future__ import annotations

import argparse
from pathlib import Path

from sfw_gym.cli.options import (
    EPISODE_ROUTERS_HELP,
    add_env,
    add_episode_runner_options,
    add_out_folder,
    add_routers,
    add_seed,
    agents_from_here,
    json_object,
    non_negative_int,
    optional_routers,
    positive_int,
    runner_settings,
)

EXAMPLE = "sfw-gym evaluate --agents frontier,regions-ppo,greedy --episodes 10 --seed 2000000"
HELP = "compare agents on the same floorplans and seeds (table, curves, paths)"


def agents_help() -> str:
    """``--agents``' help: every agent name as it is now, installed ones included
    (:func:`~sfw_gym.agents.agent_names`)."""
    from sfw_gym.agents import agent_names

    return f"comma-separated agent names: {', '.join(agent_names())}; or package.module:Class"


def add_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--agents", default="frontier,cross-pass,random", help=agents_help())
    parser.add_argument("--episodes", type=positive_int, default=10, help="episodes per agent")
    add_seed(parser, "episode i uses reset(seed=SEED + i)")
    parser.add_argument(
        "--floorplans",
        default=None,
        help="folder of plan files, JSON or ROS map YAML (cycled), or one file (default: the "
        "env's procedural plans)",
    )
    add_routers(parser, EPISODE_ROUTERS_HELP)
    add_env(parser)
    parser.add_argument("--env-kwargs", default=None, help="extra gym.make kwargs as JSON")
    parser.add_argument(
        "--agent-params", default=None, help='per-agent parameters as JSON: {"frontier": {...}}'
    )
    add_out_folder(parser, "evaluation", "output folder (resumes from it)")
    add_episode_runner_options(parser)
    parser.add_argument(
        "--vector-envs",
        type=positive_int,
        default=1,
        help="N > 1: run the episodes on the native vector env of N sub-envs, stepped together "
        "in this process with one agent per sub-env, instead of --workers; the same records "
        "(no GIFs)",
    )
    parser.add_argument("--gif", action="store_true", help="also write GIFs of the first episodes")
    parser.add_argument(
        "--gif-episodes", type=non_negative_int, default=1, help="episodes per agent with a GIF"
    )


def run(args: argparse.Namespace) -> int:
    from sfw_gym.evaluation import evaluate

    agents_from_here()
    result = evaluate(
        [a.strip() for a in args.agents.split(",") if a.strip()],
        args.episodes,
        args.seed,
        out=args.out,
        env_id=args.env,
        floorplans=args.floorplans,
        routers=optional_routers(args.routers),
        env_kwargs=json_object("--env-kwargs", args.env_kwargs),
        agent_params=json_object("--agent-params", args.agent_params),
        gif_episodes=args.gif_episodes if args.gif else 0,
        vector_envs=args.vector_envs,
        **runner_settings(args),
    )
    print((Path(args.out) / "results.md").read_text(encoding="utf-8"), end="")
    paired = Path(args.out) / "paired.md"
    if paired.is_file():
        print(
            "\npaired on the same plans and seeds:",
            paired.read_text(encoding="utf-8"),
            sep="\n",
            end="",
        )
    print(f"wrote {len(result['files'])} files under {args.out}")
    return 0
