"""The map predictor's quality, size and speed (issue 46; docs/results/prediction.md).

On the cells still unknown at 25 / 50 / 75 % of frontier's 3,000-step episodes, on the test split
(50 seeds) and the 11 HouseExpo plans: free IoU, wall F1 and the AUROC of p_free and p_wall, for
the learned predictor and the two that learn nothing (every unknown cell at the training set's
class shares; the nearest known cell's class). Then its size, one prediction's time on one core
at the env's map sizes (median over the test snapshots), and its training time. The snapshots
are collected on first use (frontier on the native vector env) and kept in ``--work``.

    python scripts/benchmarks/bench_predictor.py --write-docs
    python scripts/benchmarks/bench_predictor.py --model runs/predictor/model --episodes 10
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np
from _docs import RESULTS, command_line, machine_short, write_block

from sfw_gym.evaluation.prediction import (
    QUALITY_METRICS,
    SnapshotEpisode,
    collect_snapshots,
    load_snapshots,
    prediction_quality,
)
from sfw_gym.navigation.prediction import FreePriorPredictor, NearestKnownPredictor
from sfw_gym.rl.map_predictor import LearnedMapPredictor, predictor_record

DOC = RESULTS / "prediction.md"
MOMENTS = (750, 1500, 2250)  # 25 / 50 / 75 % of the 3,000-step budget


def snapshot_sets(args: argparse.Namespace) -> dict[str, list[Path]]:
    """The quality snapshots per set, collected where missing."""
    sets = {
        f"test ({args.episodes} seeds)": [
            SnapshotEpisode("frontier", args.seed + i, MOMENTS) for i in range(args.episodes)
        ]
    }
    plans = sorted(Path(args.floorplans).glob("*.json")) if args.floorplans else []
    if plans:
        sets[f"HouseExpo ({len(plans)} plans)"] = [
            SnapshotEpisode("frontier", args.seed + i, MOMENTS, str(p)) for i, p in enumerate(plans)
        ]
    out = {}
    for name, episodes in sets.items():
        folder = Path(args.work) / ("houseexpo" if "HouseExpo" in name else "test")
        out[name] = collect_snapshots(episodes, folder, num_envs=args.num_envs)
    return out


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--model", default=None, help="a predictor folder (default: the shipped one)")
    p.add_argument("--episodes", type=int, default=50)
    p.add_argument("--seed", type=int, default=2_000_000, help="benchmark-v1's test seeds")
    p.add_argument("--floorplans", default="../shared/floorplans/houseexpo")
    p.add_argument("--work", default="runs/predictor/quality", help="where snapshots are kept")
    p.add_argument("--num-envs", type=int, default=8)
    p.add_argument("--write-docs", action="store_true", help=f"write the tables into {DOC.name}")
    args = p.parse_args()

    learned = LearnedMapPredictor(args.model)
    record = predictor_record(args.model)
    predictors = {
        "learned": learned,
        "free prior": FreePriorPredictor(**record["unknown_prior"]),
        "nearest known": NearestKnownPredictor(),
    }
    rows = [
        "| plans | moment | predictor | free IoU | wall F1 | free AUROC | wall AUROC |",
        "|---|---|---|---:|---:|---:|---:|",
    ]
    times = []
    for set_name, files in snapshot_sets(args).items():
        episodes = [load_snapshots(f) for f in files]
        for k, step in enumerate(MOMENTS):
            taken = [(e, k) for e in episodes if k < len(e.codes) and e.steps[k] == step]
            for name, predictor in predictors.items():
                maps, codes, truths = [], [], []
                for e, i in taken:
                    begin = time.perf_counter()
                    maps.append(predictor.predict_codes(e.codes[i], e.proximity))
                    if name == "learned":
                        times.append(time.perf_counter() - begin)
                    codes.append(e.codes[i])
                    truths.append(e.truth)
                q = prediction_quality(maps, codes, truths)
                cells = " | ".join(f"{q[m]:.3f}" for m in QUALITY_METRICS)
                moment = f"{100 * step // 3000} % ({len(taken)})"
                rows.append(f"| {set_name} | {moment} | {name} | {cells} |")
    model = learned.path / "model.pt"
    trained_s = float(record.get("training_seconds", "nan"))
    facts = [
        f"- parameters: {record['parameters']:,}; weights {model.stat().st_size / 2**20:.2f} MB",
        f"- one prediction, one core: median {1000 * np.median(times):.1f} ms, 90th percentile "
        f"{1000 * np.percentile(times, 90):.1f} ms over {len(times)} test and HouseExpo maps",
        f"- trained on {record['snapshots']:,} snapshots of {record['episodes']} episodes "
        f"({record.get('steps_done', record['training']['steps']):,} steps of "
        f"{record['training']['batch']} crops of {record['training']['crop']} cells, "
        f"{record['training']['threads']} thread(s))"
        + (f" in {trained_s / 60:.0f} min" if np.isfinite(trained_s) else ""),
    ]
    facts.append(
        f"- 1-minute load average {os.getloadavg()[0]:.1f} at the end (others share the cores)"
    )
    print("\n".join([*rows, "", *facts]))
    if args.write_docs:
        lines = [f"`{command_line()}` ({machine_short()}):", "", *rows, "", *facts]
        write_block(DOC, "bench_predictor", lines)


if __name__ == "__main__":
    main()
