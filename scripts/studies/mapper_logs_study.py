"""Mapping recorded logs: our mapper's options vs the SfW authors' method, paired (issue 31).

For every plan (``--generated`` generated ones and the HouseExpo files) and router count (1, 2),
records a log with :func:`sfw_gym.evaluation.logs.record_log` (a person's walk, the SfW CSV
layout, the disagreeing radio: shadowing, per-router/band transmit offsets, dearer walls at 5 GHz,
missed readings), maps it with every method through :func:`sfw_gym.mapping.offline.map_log`
exactly as ``sfw-gym map`` does, and scores each map on the recorded truth. Prints, per router
count, the mean of each metric per method and each method's paired difference from the reference
with its 95 % interval (the package's paired comparison, a seeded bootstrap over logs); writes
every row to ``OUT/rows.csv``.

    python scripts/studies/mapper_logs_study.py --generated 10 --out runs/logs_study
"""

from __future__ import annotations

import argparse
import csv
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from sfw_gym.evaluation.logs import read_log_meta, record_log, score_map
from sfw_gym.evaluation.stats import compare_paired
from sfw_gym.mapping import MapperConfig
from sfw_gym.mapping.offline import map_log
from sfw_gym.world import generate_floorplan, load_floorplan

HOUSEEXPO = Path(__file__).resolve().parents[3] / "shared" / "floorplans" / "houseexpo"
METRICS = ("free_iou", "wall_precision", "interior_wall_recall")
REFERENCE = "sfw-reference"
#: label -> map_log keyword arguments (ours: no calibration, as for a log from elsewhere;
#: "all+2pass" is map_log's default)
METHODS = {
    REFERENCE: {"method": "sfw-reference"},
    "strongest": {"config": MapperConfig(router_policy="strongest"), "passes": 1},
    "all": {"config": MapperConfig(router_policy="all"), "passes": 1},
    "strongest+2pass": {"config": MapperConfig(router_policy="strongest"), "passes": 2},
    "all+2pass": {"config": MapperConfig(router_policy="all"), "passes": 2},
    "all+2.4GHz": {"config": MapperConfig(router_policy="all"), "rssi_column": "2.4"},
}


def run(job: tuple[str, int, Path, tuple[str, ...], str]) -> list[dict]:
    source, n_routers, out, methods, trajectory = job
    plan = (
        generate_floorplan(int(source[4:])) if source.startswith("gen:") else load_floorplan(source)
    )
    name = source if source.startswith("gen:") else Path(source).stem[:10]
    csv_path = out / f"{name.replace(':', '')}_{n_routers}r.csv"
    record_log(plan, csv_path, routers=n_routers, seed=7, trajectory=trajectory)
    meta = read_log_meta(csv_path)
    rows = []
    for label in methods:
        kwargs = METHODS[label]
        if n_routers == 1 and "rssi_column" in kwargs:
            continue
        res = map_log(
            csv_path, meta["routers_px"], scale_m_per_unit=meta["pixel_m"], progress=False, **kwargs
        )
        scores = score_map(res.occupancy_u8, res.grid, meta["truth_u8"], meta["truth_grid"])
        rows.append(
            {
                "plan": name,
                "routers": n_routers,
                "samples": meta["samples"],
                "method": label,
                "us_mean": res.us_per_sample,
                **{m: scores[m] for m in METRICS},
            }
        )
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--generated", type=int, default=10)
    parser.add_argument("--houseexpo", type=Path, default=HOUSEEXPO)
    parser.add_argument("--methods", default=",".join(METHODS))
    parser.add_argument("--trajectory", choices=["walk", "survey"], default="walk")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--out", type=Path, default=Path("runs/logs_study"))
    args = parser.parse_args()
    methods = tuple(m.strip() for m in args.methods.split(","))
    unknown = [m for m in methods if m not in METHODS]
    if unknown:
        parser.error(f"unknown methods {unknown}; known: {list(METHODS)}")
    args.out.mkdir(parents=True, exist_ok=True)
    sources = [f"gen:{s}" for s in range(args.generated)]
    sources += [str(p) for p in sorted(args.houseexpo.glob("*.json"))]
    jobs = [(s, r, args.out, methods, args.trajectory) for r in (1, 2) for s in sources]
    with ProcessPoolExecutor(args.workers) as pool:
        rows = [row for part in pool.map(run, jobs) for row in part]
    with open(args.out / "rows.csv", "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    for n_routers in (1, 2):
        here = [r for r in rows if r["routers"] == n_routers]
        plans = sorted({r["plan"] for r in here})
        print(f"\n## {n_routers} router(s): {len(plans)} logs, mean (paired difference from "
              f"{REFERENCE} [95 % CI])\n")  # fmt: skip
        print("| method | " + " | ".join(METRICS) + " | µs/sample |")
        print("|---" * (len(METRICS) + 2) + "|")
        table = {(r["plan"], r["method"]): r for r in here}
        for label in methods:
            if (plans[0], label) not in table:
                continue
            cells = []
            for m in METRICS:
                vals = np.array([table[p, label][m] for p in plans], float)
                ref = np.array([table[p, REFERENCE][m] for p in plans], float)
                cell = f"{np.nanmean(vals):.3f}"
                if label != REFERENCE and REFERENCE in methods:
                    d = compare_paired(ref, vals)
                    cell += f" ({d.text('{:+.3f}')}, n={d.n})"
                cells.append(cell)
            us = np.mean([table[p, label]["us_mean"] for p in plans])
            print(f"| {label} | " + " | ".join(cells) + f" | {us:.1f} |")


if __name__ == "__main__":
    main()
