"""Paired comparison of two evaluation runs of the same agent on the same plans and seeds.

Usage::

    python scripts/studies/compare_runs.py BEFORE/episodes.jsonl AFTER/episodes.jsonl \
        [--agent frontier]

Episodes are paired by seed; for each metric it prints both means and the mean of the paired
differences (after − before) with its 95 % interval: the package's one paired comparison
(``sfw_gym.evaluation.stats.paired_comparison``, a seeded bootstrap over the pairs, as
``sfw-gym evaluate`` and ``sfw-gym benchmark compare``), in the same table.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from sfw_gym.evaluation.checkpoint import load_checkpoint
from sfw_gym.evaluation.report import paired_table
from sfw_gym.evaluation.stats import paired_comparison

METRICS = ("coverage", "info_gain_per_m", "free_iou", "wall_precision", "path_length_m", "wall_s")


def load(path: Path, agent: str) -> dict[int, dict]:
    """Records of ``agent`` in an ``episodes.jsonl``, by seed."""
    return {r["seed"]: r for r in load_checkpoint(path) if r["agent"] == agent}


def compare_runs(before: dict[int, dict], after: dict[int, dict], agent: str) -> str:
    """The paired table (after − before) over the seeds both runs hold."""
    seeds = sorted(set(before) & set(after))
    if not seeds:
        raise SystemExit(f"no seed of {agent!r} in both runs")
    differences = paired_comparison([(before[s], after[s]) for s in seeds], METRICS)
    table = paired_table([(agent, differences)], group="agent", a="before", b="after")
    ratio = [after[s]["wall_s"] / before[s]["wall_s"] for s in seeds]
    return (
        f"{agent}: {len(seeds)} paired episodes\n\n{table}\n"
        f"wall time after/before: median {np.median(ratio):.2f} (episodes on different loads)\n"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("before", type=Path)
    parser.add_argument("after", type=Path)
    parser.add_argument("--agent", default="frontier")
    args = parser.parse_args()
    before, after = load(args.before, args.agent), load(args.after, args.agent)
    print(f"{args.before} vs {args.after}")
    print(compare_runs(before, after, args.agent), end="")


if __name__ == "__main__":
    main()
