"""``sfw-gym benchmark``: ``benchmark run`` takes an agent through the benchmark protocol's
fixed splits; ``benchmark compare`` pairs two results files."""

from __future__ import annotations

import argparse
from pathlib import Path

from sfw_gym.cli.options import (
    EPISODE_ROUTERS_HELP,
    add_command,
    add_episode_runner_options,
    add_out_folder,
    add_routers,
    add_seed,
    agents_from_here,
    json_object,
    optional_routers,
    positive_int,
    runner_settings,
)

EXAMPLE = "sfw-gym benchmark run --agent frontier --split test"
HELP = "run an agent through the benchmark protocol, or compare two results files"
DESCRIPTION = (
    "sfw-gym benchmark run --agent AGENT [options] | sfw-gym benchmark compare "
    "A.json B.json (a bare 'sfw-gym benchmark --agent AGENT' runs too)"
)


def add_options(parser: argparse.ArgumentParser) -> None:
    actions = parser.add_subparsers(dest="action", metavar="{run,compare}", required=True)
    bench_run = add_command(
        actions, "run", run, help="run an agent through the protocol → OUT/results.*"
    )
    bench_run.add_argument(
        "--agent", required=True, help="a shipped agent name or package.module:Class of your own"
    )
    bench_run.add_argument("--protocol", default="benchmark-v1", help="protocol name or YAML path")
    bench_run.add_argument(
        "--split",
        default="test",
        choices=["train", "validation", "test"],
        help="the protocol's split to run: its plans and seeds",
    )
    bench_run.add_argument("--agent-params", default=None, help="the agent's parameters as JSON")
    add_seed(bench_run, "the agent seed")
    bench_run.add_argument(
        "--plans",
        default=None,
        help="a folder of plan files, JSON or ROS map YAML, to add (by the split)",
    )
    add_routers(bench_run, EPISODE_ROUTERS_HELP)
    bench_run.add_argument(
        "--episodes", type=positive_int, default=None, help="at most this many episodes per env"
    )
    add_out_folder(
        bench_run, None, "output folder (resumes from it) (default: benchmark/AGENT/SPLIT)"
    )
    add_episode_runner_options(bench_run)
    compare = add_command(actions, "compare", run, help="pair two results.json files (B − A)")
    compare.add_argument("results", nargs=2, metavar="RESULTS", help="A.json B.json")


def bare_runs(argv: list[str]) -> list[str]:
    """The form before the subcommands, ``benchmark --agent A ...``, read as ``benchmark run``."""
    i = next((j for j, token in enumerate(argv) if not token.startswith("-")), None)
    if i is not None and argv[i] == "benchmark":
        rest = argv[i + 1 :]
        if rest and rest[0] not in ("run", "compare", "-h", "--help"):
            return [*argv[: i + 1], "run", *rest]
    return argv


def run(args: argparse.Namespace) -> int:
    from sfw_gym.evaluation import benchmark

    if args.action == "compare":
        a, b = (benchmark.load_results(p) for p in args.results)
        print(benchmark.compare(a, b), end="")
        return 0
    agents_from_here()
    out = args.out or f"benchmark/{args.agent.replace(':', '.')}/{args.split}"
    benchmark.run_benchmark(
        args.agent,
        protocol=args.protocol,
        split=args.split,
        out=out,
        agent_params=json_object("--agent-params", args.agent_params),
        agent_seed=args.seed,
        plans=args.plans,
        routers=optional_routers(args.routers),
        episodes=args.episodes,
        **runner_settings(args),
    )
    print((Path(out) / "results.md").read_text(encoding="utf-8"), end="")
    print(f"wrote {out}/results.json and results.md")
    return 0
