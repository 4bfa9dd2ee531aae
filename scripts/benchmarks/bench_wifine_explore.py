"""Frontier, cross-pass and the learned explorer (regions-ppo) on WiFine's three office floors
(issue 38): real buildings of ~90 x 58 m in the explore env.

    python scripts/benchmarks/bench_wifine_explore.py [--wifine ../shared/datasets/wifine]
        [--steps 3000] [--seeds 1] [--out wifine-explore] [--figure docs/figures/wifine_explore.png]

Each floor's layout (``floor_layouts/Floor_{4,5,6}_10cm.png``: 0.1 m per pixel, the origin at the
image's bottom-left corner) is loaded through a ROS map YAML written in ``OUT/maps``; then
:func:`sfw_gym.evaluation.evaluate` runs the agents on ``SfW-Explore-v0`` (two routers) with a
budget of ``--steps`` steps, episode ``i`` with ``reset(seed=i)`` (the same routers and start for
every agent), in ``OUT/floor_<n>/`` (its results.md, curves and trajectories). Prints the table of
coverage and bits per metre (mean ± 95 % CI over the seeds) and writes it to ``OUT/table.md``;
the seed-0 trajectory figures of the three floors, stacked, go to ``--figure``.

Results: docs/results/agents.md#real-office-floors; writes docs/figures/wifine_explore.png
(``--figure``: the seed-0 trajectories of the three floors, stacked).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
from PIL import Image

from sfw_gym.datasets import WIFINE_FLOORS, write_wifine_maps
from sfw_gym.evaluation import evaluate
from sfw_gym.world import load_floorplan

REPO = Path(__file__).resolve().parents[2]
AGENTS = ("frontier", "cross-pass", "regions-ppo")
ENV_ID = "SfW-Explore-v0"


def stack_figures(paths: list[Path], out: Path) -> Path:
    """The figures one above the other on white, quantised to 64 colours (a small PNG)."""
    images = [np.asarray(Image.open(p).convert("RGB")) for p in paths]
    width = max(im.shape[1] for im in images)
    rows = [
        np.pad(im, ((0, 0), (0, width - im.shape[1]), (0, 0)), constant_values=255) for im in images
    ]
    stacked = Image.fromarray(np.concatenate(rows, axis=0))
    out.parent.mkdir(parents=True, exist_ok=True)
    stacked.quantize(64, method=Image.Quantize.MEDIANCUT).save(out, optimize=True)
    return out


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--wifine", type=Path, default=REPO.parent / "shared" / "datasets" / "wifine")
    p.add_argument(
        "--steps", type=int, default=3000, help="step budget of an episode (the env's default)"
    )
    p.add_argument("--seeds", type=int, default=1, help="episodes per floor and agent")
    p.add_argument("--out", type=Path, default=Path("wifine-explore"))
    p.add_argument("--figure", type=Path, default=REPO / "docs" / "figures" / "wifine_explore.png")
    p.add_argument("--workers", type=int, default=1, help="worker processes (1: this one)")
    args = p.parse_args()
    maps = write_wifine_maps(args.wifine / "floor_layouts", args.out / "maps")
    lines = [
        "| floor | free area [m²] | agent | coverage | bits / m | path [m] | episode wall [s] |",
        "|---|---:|---|---:|---:|---:|---:|",
    ]
    figures = []
    for floor_id, path in maps.items():
        floor = WIFINE_FLOORS[floor_id]
        area = load_floorplan(path).area_m2
        start = time.perf_counter()
        result = evaluate(
            AGENTS,
            args.seeds,
            0,
            out=args.out / f"floor_{floor}",
            env_id=ENV_ID,
            floorplans=path,
            env_kwargs={"max_steps": args.steps},
            workers=args.workers,
            progress=False,
        )
        print(f"floor {floor}: {time.perf_counter() - start:.0f} s", flush=True)
        for row in result["rows"]:
            walls = [r["wall_s"] for r in result["records"] if r["agent"] == row["agent"]]
            lines.append(
                f"| {floor} | {area:,.0f} | {row['agent']} | {_cell(row, 'coverage', 3)} | "
                f"{_cell(row, 'info_gain_per_m', 1)} | {_cell(row, 'path_length_m', 0)} | "
                f"{np.mean(walls):.0f} |"
            )
        figures += [f for f in result["files"] if f.parent.name == "trajectories"][:1]
    table = "\n".join(lines) + "\n"
    (args.out / "table.md").write_text(table)
    print(table)
    print(f"wrote {args.out / 'table.md'} and {stack_figures(figures, args.figure)}")


def _cell(row: dict, key: str, digits: int) -> str:
    mean, ci = row[f"{key}_mean"], row[f"{key}_ci95"]
    text = f"{mean:.{digits}f}"
    return text if row[f"{key}_n"] < 2 else f"{text} ± {ci:.{digits}f}"


if __name__ == "__main__":
    main()
