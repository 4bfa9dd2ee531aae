"""Tune ``predict-explore`` on the validation split (issue 46): each setting against frontier on
the same seeds, bits per metre and coverage as ratios with 95 % paired intervals.

    python scripts/studies/predict_explore_sweep.py --episodes 20 \
        --settings '[{}, {"distance_offset_m": 0.5}, {"predictor": "nearest"}]'

Each setting runs as its own evaluation in ``--out``/``<n>`` (resumable); frontier once in
``--out``/frontier. The validation seeds start at 1,000,000 (benchmark-v1's split).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from sfw_gym.evaluation.runner import evaluate
from sfw_gym.evaluation.stats import compare_paired


def run(agent: str, params: dict, out: Path, args: argparse.Namespace) -> dict[int, dict]:
    result = evaluate(
        [agent], args.episodes, args.seed, out=out, agent_params={agent: params},
        workers=args.workers, progress=False, floorplans=args.floorplans,
    )  # fmt: skip
    return {r["episode"]: r for r in result["records"]}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--settings", default="[{}]", help="a JSON list of predict-explore settings")
    p.add_argument("--episodes", type=int, default=20)
    p.add_argument("--seed", type=int, default=1_000_000, help="benchmark-v1's validation seeds")
    p.add_argument("--floorplans", default=None)
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--out", default="runs/predict_sweep")
    args = p.parse_args()
    out = Path(args.out)
    ref = run("frontier", {}, out / "frontier", args)
    print("| setting | bits/m ratio | coverage ratio | ms / step (x frontier) |")
    print("|---|---|---|---:|")
    ref_ms = sum(r["wall_s"] for r in ref.values()) / sum(r["steps"] for r in ref.values())
    for n, params in enumerate(json.loads(args.settings)):
        recs = run("predict-explore", params, out / str(n), args)
        eps = sorted(set(ref) & set(recs))

        def col(rs: dict[int, dict], k: str, eps: list[int] = eps) -> np.ndarray:
            return np.array([float(rs[i][k]) for i in eps])

        rb = compare_paired(col(ref, "info_gain_per_m"), col(recs, "info_gain_per_m"), ratio=True)
        rc = compare_paired(col(ref, "coverage"), col(recs, "coverage"), ratio=True)
        ms = sum(recs[i]["wall_s"] for i in eps) / sum(recs[i]["steps"] for i in eps)
        print(
            f"| `{json.dumps(params)}` | {rb.text('{:.3f}')} | {rc.text('{:.3f}')} | "
            f"{ms / ref_ms:.2f} |",
            flush=True,
        )


if __name__ == "__main__":
    main()
