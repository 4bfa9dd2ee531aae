"""The earlier PPO waypoint policy (``waypoint-ppo``) vs frontier on held-out plans (issue 6).

Usage: ``python scripts/studies/compare_ppo_frontier.py [--episodes 50] [--seed 2000000]
[--model agents/ppo/SfW-Explore-v0_1] [--out runs/ppo_vs_frontier] [--workers 2]``

Same as ``sfw-gym evaluate --agents waypoint-ppo,frontier --episodes 50 --seed 2000000``, plus a
check that no evaluation floorplan occurs in the policy's training logs (the monitor CSVs record the
floorplan of every training and held-out episode), then the Markdown table.
"""

from __future__ import annotations

import argparse
import csv
from pathlib import Path

from sfw_gym.core.data import DEFAULT_WAYPOINT_MODEL_DIR
from sfw_gym.evaluation import evaluate


def trained_floorplans(model_dir: Path) -> set[str]:
    """Floorplan names of every episode in the model's monitor logs."""
    names: set[str] = set()
    for path in model_dir.glob("*.monitor.csv"):
        lines = path.read_text(encoding="utf-8").splitlines()[1:]  # skip the JSON header
        names |= {row["floorplan"] for row in csv.DictReader(lines) if row.get("floorplan")}
    return names


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--episodes", type=int, default=50)
    p.add_argument("--seed", type=int, default=2_000_000)
    p.add_argument("--model", default=str(DEFAULT_WAYPOINT_MODEL_DIR))
    p.add_argument("--out", default="runs/ppo_vs_frontier")
    p.add_argument("--workers", type=int, default=2)
    args = p.parse_args()
    out = Path(args.out)
    result = evaluate(
        ["waypoint-ppo", "frontier"],
        args.episodes,
        args.seed,
        out=out,
        # sampled from the agent's seeded generator, as measured (its default is the mode)
        agent_params={"waypoint-ppo": {"path": args.model, "deterministic": False}},
        workers=args.workers,
    )
    seen = trained_floorplans(Path(args.model))
    plans = {r["floorplan"] for r in result["records"]}
    print(
        f"{len(plans)} evaluation floorplans; {len(seen)} in the training logs; "
        f"overlap: {sorted(plans & seen) or 'none'}"
    )
    print((out / "results.md").read_text(encoding="utf-8"))


if __name__ == "__main__":
    main()
