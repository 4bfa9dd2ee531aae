"""Figures of an oracle's and frontier's trajectories on chosen episodes of finished
evaluations (issue 40): each RUN:EPISODE gives one figure (the true plan with both paths, and
each agent's final belief), written as OUT_<plan>.png: with the default ``--out``, it writes
docs/figures/ceiling_<plan>.png (docs/results/ceiling.md).

    python scripts/figures/plot_ceiling_trajectories.py runs/ceiling_test:3 runs/ceiling_hx:0 \\
        --agents frontier,oracle-coverage --out docs/figures/ceiling
"""

from __future__ import annotations

import argparse
import json
import shutil
import tempfile
from pathlib import Path

from sfw_gym.evaluation.plots import plot_trajectories


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("episodes", nargs="+", metavar="RUN:EPISODE")
    p.add_argument("--agents", default="frontier,oracle-coverage")
    p.add_argument("--out", default="docs/figures/ceiling")
    args = p.parse_args()
    agents = args.agents.split(",")
    for item in args.episodes:
        run, _, episode = item.rpartition(":")
        lines = Path(run, "episodes.jsonl").read_text(encoding="utf-8").splitlines()
        records = [
            r
            for r in map(json.loads, lines)
            if r["episode"] == int(episode) and r["agent"] in agents
        ]
        with tempfile.TemporaryDirectory() as tmp:  # the run's own figures stay as they are
            (Path(tmp) / "episodes").symlink_to(Path(run, "episodes").resolve())
            for figure in plot_trajectories(records, agents, Path(tmp)):
                plan = figure.stem.split("_", 1)[1]
                target = Path(f"{args.out}_{plan}.png")
                target.parent.mkdir(parents=True, exist_ok=True)
                shutil.copyfile(figure, target)
                print(target)


if __name__ == "__main__":
    main()
