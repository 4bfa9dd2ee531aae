"""The shipped agents on benchmark-v1 / test: runs each through `sfw-gym benchmark` (resuming
what is done) and writes the table into docs/benchmark.md between its markers; ``--oracles``
runs the oracles (privileged, never among the shipped agents) into the oracles' table.

    python scripts/benchmarks/benchmark_shipped.py [--workers 2] [--out runs/benchmark]
    python scripts/benchmarks/benchmark_shipped.py --oracles  # oracle-regions: 5 episodes per env
    python scripts/benchmarks/benchmark_shipped.py --agents regions-ppo,region-teacher

Results: docs/benchmark.md#the-shipped-agents-on-benchmark-v1--test, between
``<!-- benchmark:begin -->`` and ``<!-- benchmark:end -->`` (``<!-- oracles:begin -->`` /
``:end -->`` with ``--oracles``); docs/results/agents.md#learned-vs-frontier includes that table.
The rows are labelled with the registry's names (``sfw_gym.agents.AGENTS``: ``regions-ppo``,
``goals-ppo``, ``waypoint-ppo``, ...), never the deprecated ``ppo`` / ``ppo-goals`` /
``ppo-waypoint``, whose meaning changed over time. A whole run takes hours on 2 cores (the
agents' episodes, 70 per agent); ``--out`` resumes one. ``--agents`` runs some of them and
keeps the table's rows of the others as they are (the agents are deterministic, so a row stands
until its agent changes).
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))  # _docs beside it, however it is loaded
from _docs import ROOT, markers, write_block

from sfw_gym.agents import AGENTS, is_privileged
from sfw_gym.evaluation.benchmark import format_interval, run_benchmark
from sfw_gym.evaluation.metric_table import METRICS
from sfw_gym.evaluation.report import PRIVILEGED_NOTE, agent_label

DOC = ROOT / "docs" / "benchmark.md"
COLUMNS = ("coverage", "info_gain_per_m", "path_length_m", "free_iou", "wall_precision", "ate_m")


#: Episodes per env of the agents too slow for the whole split (~1 min an episode).
EPISODE_CAPS = {"oracle-regions": 5}


def shipped_agents() -> list[str]:
    """Every registered agent but the oracles (privileged: run them by name)."""
    return [name for name in AGENTS if not is_privileged(name)]


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--out", default="runs/benchmark")
    p.add_argument("--split", default="test")
    p.add_argument(
        "--oracles",
        action="store_true",
        help="run the oracles instead (privileged) into the doc's oracle table",
    )
    p.add_argument("--agents", help="comma-separated: run these only, keep the others' rows")
    args = p.parse_args()
    names = [n for n in AGENTS if is_privileged(n)] if args.oracles else shipped_agents()
    if args.agents:
        unknown = sorted(set(args.agents.split(",")) - set(names))
        if unknown:
            p.error(f"--agents: {unknown} are not among {names}")
        names = [n for n in names if n in args.agents.split(",")]
    results = {
        name: run_benchmark(
            name,
            split=args.split,
            out=Path(args.out) / name,
            workers=args.workers,
            episodes=EPISODE_CAPS.get(name),
        )
        for name in names
    }
    block = "oracles" if args.oracles else "benchmark"
    lines = table(results, kept_rows(DOC, block) if args.agents else {})
    if args.oracles:
        lines += ["", PRIVILEGED_NOTE]
    write_block(DOC, block, lines)
    print("\n".join(lines))


def kept_rows(doc: Path, block: str) -> dict[str, dict[str, str]]:
    """The block's current table rows, by env id and agent name (a table of the earlier layout,
    with the episodes in the env's heading, gets them as its second column)."""
    begin, end = markers(block)
    text = doc.read_text(encoding="utf-8").split(begin)[1].split(end)[0]
    rows: dict[str, dict[str, str]] = {}
    parts = re.split(r"^\*\*(\S+)\*\*(?: \((\d+) episodes\))?$", text, flags=re.M)
    for env_id, episodes, body in zip(parts[1::3], parts[2::3], parts[3::3], strict=True):
        for line in body.splitlines():
            cells = [c.strip() for c in line.strip("|").split("|")]
            if line.startswith("| ") and cells[0].rstrip(" †") in AGENTS:
                if episodes:
                    cells.insert(1, episodes)
                rows.setdefault(env_id, {})[cells[0].rstrip(" †")] = "| " + " | ".join(cells) + " |"
    return rows


def table(results: dict[str, dict], kept: dict[str, dict[str, str]]) -> list[str]:
    """The results as a Markdown table per env (oracles marked †), beside the ``kept`` rows of
    agents not run now, in the registry's order."""
    first = next(iter(results.values()))
    flags = " --oracles" if first.get("privileged") else ""
    lines = [
        f"`python scripts/benchmarks/benchmark_shipped.py{flags}` "
        f"(sfw_gym {first['package_version']}, "
        f"{first['protocol']} / {first['split']}, agent seed 0; mean [95 % bootstrap interval]; "
        "`sfw-gym benchmark compare` gives any pair's paired differences).",
    ]
    for env_id in first["summary"]:
        columns = [c for c in COLUMNS if any(c in r["summary"][env_id] for r in results.values())]
        lines += ["", f"**{env_id}**", ""]
        lines.append("| agent | episodes | " + " | ".join(METRICS[c].label for c in columns) + " |")
        lines.append("|---|---:|" + "---:|" * len(columns))
        rows = dict(kept.get(env_id, {}))
        for name, r in results.items():
            stats = r["summary"][env_id]
            cells = [format_interval(stats[c], c) if c in stats else "–" for c in columns]
            label = agent_label(name, r.get("privileged", False))
            n = stats["coverage"]["n"]
            rows[name] = f"| {label} | {n} | " + " | ".join(cells) + " |"
        lines += [rows[name] for name in AGENTS if name in rows]
    return lines


if __name__ == "__main__":
    main()
