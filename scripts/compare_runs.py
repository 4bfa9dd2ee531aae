"""Paired comparison of two evaluation runs of the same agent on the same plans and seeds.

Usage::

    python scripts/compare_runs.py BEFORE/episodes.jsonl AFTER/episodes.jsonl [--agent frontier]

Episodes are paired by seed; for each metric it prints both means and the mean of the paired
differences (after − before) with its 95 % confidence interval (Student t over the pairs).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from sfw_gym.evaluation.stats import ci95_half_width

METRICS = ("coverage", "info_gain_per_m", "free_iou", "wall_precision", "path_length_m", "wall_s")


def load(path: Path, agent: str) -> dict[int, dict]:
    """Records of ``agent`` in an ``episodes.jsonl``, by seed."""
    records = [json.loads(line) for line in path.read_text().splitlines() if line.strip()]
    return {r["seed"]: r for r in records if r["agent"] == agent}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("before", type=Path)
    parser.add_argument("after", type=Path)
    parser.add_argument("--agent", default="frontier")
    args = parser.parse_args()
    before, after = load(args.before, args.agent), load(args.after, args.agent)
    seeds = sorted(set(before) & set(after))
    if not seeds:
        raise SystemExit(f"no seed of {args.agent!r} in both runs")
    print(f"{args.agent}: {len(seeds)} paired episodes ({args.before} vs {args.after})")
    print(f"{'metric':<18} {'before':>10} {'after':>10} {'after − before (95% CI)':>32}")
    for metric in METRICS:
        pairs = [(before[s].get(metric), after[s].get(metric)) for s in seeds]
        pairs = [(a, b) for a, b in pairs if a is not None and b is not None]
        if len(pairs) < 2:
            continue
        a, b = np.array(pairs, np.float64).T
        d = b - a
        half = ci95_half_width(d)
        print(
            f"{metric:<18} {a.mean():>10.3f} {b.mean():>10.3f} "
            f"{d.mean():>+12.3f} [{d.mean() - half:+.3f}, {d.mean() + half:+.3f}]"
        )
    ratio = [after[s]["wall_s"] / before[s]["wall_s"] for s in seeds]
    print(f"wall time after/before: median {np.median(ratio):.2f} (episodes on different loads)")


if __name__ == "__main__":
    main()
