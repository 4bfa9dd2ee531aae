"""Copy the figures a finished run wrote into docs/figures, under the names the pages show.

Many of the published figures are files an evaluation or a study writes into its own folder
(``coverage_vs_steps.png``, ``trajectories/0003_<plan>.png``, ``maps.png``, ...); the pages show
them under a name that says which run made them. Run the command of a KIND below, then

    python scripts/figures/copy_figures.py KIND OUT

where OUT is that command's output folder. It writes, by KIND:

- ``agents-full``: after ``python scripts/studies/compare_agents.py --out OUT`` (its default env,
  ``SfW-ExploreFull-v0``): docs/figures/agents_full_generated_coverage_vs_steps.png,
  docs/figures/agents_full_houseexpo_coverage_vs_steps.png and
  docs/figures/agents_full_generated_trajectories_0003.png (docs/results/agents.md);
- ``agents-fixed``: after ``python scripts/studies/compare_agents.py --env SfW-Explore-v0 --agents
  frontier,cross-pass,greedy,random --out OUT``: docs/figures/agents_generated_<figure>.png and
  docs/figures/agents_houseexpo_<figure>.png (the curves and trajectories 0001 / 0000; the
  notebook's fixed-budget section, docs/results/history.md, made at commit a2cf03f);
- ``ppo-vs-frontier``: after ``python scripts/studies/compare_ppo_frontier.py --out OUT``:
  docs/figures/ppo_vs_frontier_<figure>.png (the curves and trajectories 0001;
  docs/results/training.md);
- ``demo``: after ``sfw-gym demo --out OUT``: docs/figures/demo_trajectories.png (its first
  episode; the README, docs/index.md and docs/results/agents.md);
- ``localize``: after ``sfw-gym localize --plans 10 --runs 3 --out OUT``:
  docs/figures/localize_gridmaps.png and docs/figures/localize_error_over_time.png
  (docs/results/localization.md);
- ``lidar``: after ``python scripts/studies/lidar_study.py --plans 1 --out OUT``:
  docs/figures/lidar_maps.png (docs/results/slam.md).

The other figures are written into docs/figures by the script that makes them:
``scripts/figures/plot_ceiling_trajectories.py`` (``ceiling_<plan>.png``),
``scripts/benchmarks/bench_wifine_explore.py`` (``wifine_explore.png``) and
``scripts/benchmarks/bench_fingerprints.py`` (``wifine_tracking.png``).
"""

from __future__ import annotations

import argparse
import shutil
from pathlib import Path

FIGURES = Path(__file__).resolve().parents[2] / "docs" / "figures"

#: KIND -> (file in the run's folder, a glob where the plan's name is part of it; name in
#: docs/figures)
KINDS: dict[str, list[tuple[str, str]]] = {
    "agents-full": [
        ("generated/coverage_vs_steps.png", "agents_full_generated_coverage_vs_steps.png"),
        ("houseexpo/coverage_vs_steps.png", "agents_full_houseexpo_coverage_vs_steps.png"),
        ("generated/trajectories/0003_*.png", "agents_full_generated_trajectories_0003.png"),
    ],
    "agents-fixed": [
        (f"{plans}/{name}.png", f"agents_{plans}_{name}.png")
        for plans in ("generated", "houseexpo")
        for name in ("coverage_vs_steps", "iou_vs_path")
    ]
    + [
        ("generated/trajectories/0001_*.png", "agents_generated_trajectories_0001.png"),
        ("houseexpo/trajectories/0000_*.png", "agents_houseexpo_trajectories_0000.png"),
    ],
    "ppo-vs-frontier": [
        ("coverage_vs_steps.png", "ppo_vs_frontier_coverage_vs_steps.png"),
        ("iou_vs_path.png", "ppo_vs_frontier_iou_vs_path.png"),
        ("trajectories/0001_*.png", "ppo_vs_frontier_trajectories_0001.png"),
    ],
    "demo": [("trajectories/0000_*.png", "demo_trajectories.png")],
    "localize": [
        ("gridmaps.png", "localize_gridmaps.png"),
        ("error_over_time.png", "localize_error_over_time.png"),
    ],
    "lidar": [("maps.png", "lidar_maps.png")],
}


def copy_figures(kind: str, run: Path, figures: Path = FIGURES) -> list[Path]:
    """Copy the figures of ``kind`` from the run folder ``run``; return the files written.
    Refuses (before copying anything) when one is missing or a glob matches several files."""
    sources = []
    for pattern, _ in KINDS[kind]:
        found = sorted(run.glob(pattern))
        if len(found) != 1:
            raise SystemExit(f"{run}: expected one {pattern}, found {len(found)}")
        sources.append(found[0])
    written = []
    for source, (_, name) in zip(sources, KINDS[kind], strict=True):
        target = figures / name
        shutil.copyfile(source, target)
        written.append(target)
    return written


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("kind", choices=sorted(KINDS))
    p.add_argument("run", type=Path, help="the output folder of the kind's command")
    args = p.parse_args()
    for path in copy_figures(args.kind, args.run):
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
