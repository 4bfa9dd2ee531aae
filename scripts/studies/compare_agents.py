"""Compare the baseline agents on generated plans and on the HouseExpo plans (issue 5's benchmark).

Usage: ``python scripts/studies/compare_agents.py [--episodes 20] [--houseexpo DIR] [--out
runs/compare] [--agents frontier,cross-pass,random] [--env SfW-ExploreFull-v0] [--workers 2]``

Runs ``sfw_gym.evaluation.evaluate`` twice — ``--episodes`` procedural plans (seeds 0, 1, …) and
one episode per HouseExpo file (seeds 100, 101, …) — into ``OUT/generated`` and ``OUT/houseexpo``
(each resumable), then prints both Markdown tables. Same as two ``sfw-gym evaluate`` calls.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from sfw_gym.evaluation import evaluate

DEFAULT_HOUSEEXPO = Path(__file__).resolve().parents[3] / "shared" / "floorplans" / "houseexpo"


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--agents", default="frontier,cross-pass,random")
    p.add_argument("--episodes", type=int, default=20, help="generated plans (default 20)")
    p.add_argument("--houseexpo", default=str(DEFAULT_HOUSEEXPO), help="HouseExpo folder")
    p.add_argument("--env", default="SfW-ExploreFull-v0")
    p.add_argument("--out", default="runs/compare")
    p.add_argument("--workers", type=int, default=2)
    args = p.parse_args()
    agents = [a for a in args.agents.split(",") if a]
    out = Path(args.out)
    runs = [("generated", args.episodes, 0, None)]
    he = Path(args.houseexpo)
    if he.is_dir():
        runs.append(("houseexpo", len(sorted(he.glob("*.json"))), 100, he))
    else:
        print(f"no HouseExpo folder at {he}: generated plans only")
    for name, episodes, seed, plans in runs:
        result = evaluate(
            agents,
            episodes,
            seed,
            out=out / name,
            env_id=args.env,
            floorplans=plans,
            workers=args.workers,
        )
        print(f"\n### {name} ({episodes} episodes, {args.env})\n")
        print((out / name / "results.md").read_text(encoding="utf-8"))
        print(f"{len(result['files'])} files in {out / name}")


if __name__ == "__main__":
    main()
