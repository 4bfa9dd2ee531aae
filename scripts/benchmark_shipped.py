"""The shipped agents on benchmark-v1 / test: runs each through `sfw-gym benchmark` (resuming
what is done) and writes the table into docs/benchmark.md between its markers.

    python scripts/benchmark_shipped.py [--workers 2] [--out runs/benchmark]
"""

from __future__ import annotations

import argparse
import re
from pathlib import Path

from sfw_gym.agents import AGENTS, is_privileged
from sfw_gym.evaluation.benchmark import format_interval, run_benchmark
from sfw_gym.evaluation.metric_table import METRICS

DOC = Path(__file__).resolve().parents[1] / "docs" / "benchmark.md"
COLUMNS = ("coverage", "info_gain_per_m", "path_length_m", "free_iou", "wall_precision", "ate_m")


def shipped_agents() -> list[str]:
    """Every registered agent but the oracles (privileged: run them by name)."""
    return [name for name in AGENTS if not is_privileged(name)]


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--out", default="runs/benchmark")
    p.add_argument("--split", default="test")
    args = p.parse_args()
    results = {
        name: run_benchmark(name, split=args.split, out=Path(args.out) / name, workers=args.workers)
        for name in shipped_agents()
    }
    first = next(iter(results.values()))
    lines = [
        f"`python scripts/benchmark_shipped.py` (sfw_gym {first['package_version']}, "
        f"{first['protocol']} / {first['split']}, agent seed 0; mean [95 % bootstrap interval]; "
        "`sfw-gym benchmark compare` gives any pair's paired differences).",
    ]
    for env_id in first["summary"]:
        columns = [c for c in COLUMNS if any(c in r["summary"][env_id] for r in results.values())]
        lines += ["", f"**{env_id}** ({first['summary'][env_id]['coverage']['n']} episodes)", ""]
        lines.append("| agent | " + " | ".join(METRICS[c].label for c in columns) + " |")
        lines.append("|---|" + "---:|" * len(columns))
        for name, r in results.items():
            stats = r["summary"][env_id]
            cells = [format_interval(stats[c], c) if c in stats else "–" for c in columns]
            lines.append(f"| {name} | " + " | ".join(cells) + " |")
    text = DOC.read_text(encoding="utf-8")
    block = "<!-- benchmark:begin -->\n" + "\n".join(lines) + "\n<!-- benchmark:end -->"
    DOC.write_text(
        re.sub(r"<!-- benchmark:begin -->.*<!-- benchmark:end -->", block, text, flags=re.S)
    )
    print("\n".join(lines))


if __name__ == "__main__":
    main()
