"""Where the gap to the coverage oracle lives (issue 51, item 1).

On validation seeds, for each agent: the true-free cells still unknown at the end of the episode,
binned by their distance to the nearest true wall, by line of sight to the router strongest there
(true radio) and by whether their room (the plan's labelled boxes) was ever entered; and the
bits the mapper gained, split by source (``SparseInverseKVisibility.last_gain_by_source``).
Then the coverage oracle with two and with all three pieces of its knowledge given up (paths on
the belief, targets among the frontiers, gain from the belief), as ratios to frontier's coverage
and bits per metre (95 % paired bootstrap).

    python scripts/studies/gap_decomposition.py --episodes 10 --out runs/gap
    python scripts/studies/gap_decomposition.py --episodes 10 --out runs/gap --write-docs
"""

from __future__ import annotations

import argparse
import itertools
import json
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import gymnasium as gym
import numpy as np
from scipy import ndimage

import sfw_gym  # noqa: F401  (registers the ids)
from sfw_gym.agents import make_agent
from sfw_gym.evaluation.benchmark import load_protocol, split_seeds
from sfw_gym.evaluation.stats import compare_paired
from sfw_gym.mapping.grid import belief_classes
from sfw_gym.mapping.sparse import GAIN_SOURCES

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from _docs import RESULTS, write_block

ORACLE = "sfw_gym.agents.coverage_oracle:CoverageOracle"
GIVE_UP = {"paths": {"plan_on": "belief"}, "targets": {"targets_from": "frontiers"},
           "gain": {"gain_from": "belief"}}  # fmt: skip
#: label -> (agent name or entry, parameters)
AGENTS: dict[str, tuple[str, dict]] = {
    "frontier": ("frontier", {}),
    "predict-explore": ("predict-explore", {}),
    "oracle-coverage †": ("oracle-coverage", {}),
    "oracle less paths + targets †": (ORACLE, {**GIVE_UP["paths"], **GIVE_UP["targets"]}),
    "oracle less paths + gain †": (ORACLE, {**GIVE_UP["paths"], **GIVE_UP["gain"]}),
    "oracle less targets + gain †": (ORACLE, {**GIVE_UP["targets"], **GIVE_UP["gain"]}),
    "oracle less all three †": (ORACLE, {k: v for d in GIVE_UP.values() for k, v in d.items()}),
}
WALL_BINS_M = (0.25, 0.5)
DECOMPOSED = ("frontier", "predict-explore", "oracle-coverage †")


def run(label: str, seed: int, max_steps: int) -> dict:
    """One episode: the final figures, the bits by source and the unknown free cells' bins."""
    name, params = AGENTS[label]
    env = gym.make("SfW-Explore-v0", max_steps=max_steps)
    obs, info = env.reset(seed=seed)
    u = env.unwrapped
    agent = make_agent(name, **params)
    agent.reset(env, seed=seed)
    sources = dict.fromkeys(GAIN_SOURCES, 0.0)
    entropy0 = u.mapper.entropy_bits
    done = False
    while not done:
        n = u.mapper.n_updates
        obs, _, terminated, truncated, info = env.step(agent.act(obs))
        done = terminated or truncated
        if u.mapper.n_updates > n:
            for k, v in u.mapper.last_gain_by_source.items():
                sources[k] += v
    gt = u.ground_truth()
    truth_free = gt.truth_u8 == 255
    _, _, unknown = belief_classes(u.mapper.occupancy_u8)
    left = truth_free & unknown
    res = gt.grid.resolution_m
    wall_m = ndimage.distance_transform_edt(gt.truth_u8 != 0) * res
    rows, cols = np.nonzero(left)
    xy = gt.grid.cell_to_world(np.stack([rows, cols], 1)) if len(rows) else np.zeros((0, 2))
    bins: dict[str, float] = {}
    d = wall_m[rows, cols]
    edges = (0.0, *WALL_BINS_M, np.inf)
    for lo, hi in itertools.pairwise(edges):
        bins[f"wall {lo:g}-{hi:g} m"] = float(((d >= lo) & (d < hi)).sum())
    if len(xy):
        k = gt.radio.true_k(xy)
        strongest = np.argmax(gt.radio.mean_rssi(xy), axis=1)
        sight = k[np.arange(len(xy)), strongest] == 0
    else:
        sight = np.zeros(0, bool)
    bins["in sight"] = float(sight.sum())
    bins["out of sight"] = float((~sight).sum())
    entered = np.zeros(len(xy), bool)
    in_room = np.zeros(len(xy), bool)
    path = gt.trajectory
    for room in gt.floorplan.rooms:
        x0, y0, x1, y1 = room.box
        inside = (xy[:, 0] >= x0) & (xy[:, 0] <= x1) & (xy[:, 1] >= y0) & (xy[:, 1] <= y1)
        visited = ((path[:, 0] >= x0) & (path[:, 0] <= x1) & (path[:, 1] >= y0)
                   & (path[:, 1] <= y1)).any()  # fmt: skip
        in_room |= inside
        entered |= inside & visited
    bins["room entered"] = float(entered.sum())
    bins["room never entered"] = float((in_room & ~entered).sum())
    bins["in no room"] = float((~in_room).sum())
    return {
        "label": label,
        "seed": seed,
        "coverage": float(info["coverage"]),
        "bits_per_m": float((entropy0 - u.mapper.entropy_bits) / max(info["path_length_m"], 1e-9)),
        "bits": float(entropy0 - u.mapper.entropy_bits),
        "sources": sources,
        "free_cells": float(truth_free.sum()),
        "left_unknown": float(left.sum()),
        "bins": bins,
    }


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--episodes", type=int, default=10)
    p.add_argument("--max-steps", type=int, default=3000)
    p.add_argument("--out", default="runs/gap")
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--write-docs", action="store_true", help="write the tables into the docs")
    args = p.parse_args()
    first, _ = split_seeds(load_protocol(), "validation")
    seeds = [first + i for i in range(args.episodes)]
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    done_path = out / "episodes.jsonl"
    rows = (
        [json.loads(line) for line in done_path.read_text().splitlines()]
        if done_path.exists()
        else []
    )
    have = {(r["label"], r["seed"]) for r in rows}
    todo = [(label, s) for label in AGENTS for s in seeds if (label, s) not in have]
    with ProcessPoolExecutor(args.workers) as pool, done_path.open("a") as f:
        futures = [pool.submit(run, label, s, args.max_steps) for label, s in todo]
        for fut in futures:
            row = fut.result()
            rows.append(row)
            f.write(json.dumps(row) + "\n")
            f.flush()
    by = {(r["label"], r["seed"]): r for r in rows}
    text = tables(by, seeds, args)
    print(text)
    if args.write_docs:
        write_block(RESULTS / "rollout.md", "gap_decomposition", text.splitlines())


def tables(by: dict, seeds: list[int], args: argparse.Namespace) -> str:
    """The three tables as markdown."""
    cmd = f"python scripts/studies/gap_decomposition.py --episodes {args.episodes} --out {args.out}"
    lines = [
        f"`{cmd}` (validation seeds {seeds[0]:,}-{seeds[-1]:,}, {args.max_steps:,} steps):",
        "",
    ]
    bin_names = list(by[(DECOMPOSED[0], seeds[0])]["bins"])
    lines += [
        "True-free cells still unknown at the end (mean per episode; share of them in each bin):",
        "",
        "| agent | left unknown | " + " | ".join(bin_names) + " |",
        "|---|---:|" + "---:|" * len(bin_names),
    ]
    for label in DECOMPOSED:
        rs = [by[(label, s)] for s in seeds]
        left = np.mean([r["left_unknown"] for r in rs])
        frac = np.mean([r["left_unknown"] / r["free_cells"] for r in rs])
        n_left = max(np.sum([r["left_unknown"] for r in rs]), 1)
        shares = [np.sum([r["bins"][b] for r in rs]) / n_left for b in bin_names]
        lines.append(f"| {label} | {left:.0f} ({frac:.1%} of free) | "
                     + " | ".join(f"{x:.0%}" for x in shares) + " |")  # fmt: skip
    lines += [
        "",
        "Bits gained by source (mean per episode; share of the episode's bits):",
        "",
        "| agent | bits | " + " | ".join(GAIN_SOURCES).replace("_", " ") + " |",
        "|---|---:|" + "---:|" * len(GAIN_SOURCES),
    ]
    for label in DECOMPOSED:
        rs = [by[(label, s)] for s in seeds]
        total = np.mean([r["bits"] for r in rs])
        cells = [np.mean([r["sources"][k] for r in rs]) for k in GAIN_SOURCES]
        lines.append(f"| {label} | {total:.0f} | "
                     + " | ".join(f"{c:.0f} ({c / total:.0%})" for c in cells) + " |")  # fmt: skip
    lines += [
        "",
        "The coverage oracle less pieces of its knowledge, against frontier (ratio of the means, "
        "95 % paired bootstrap):",
        "",
        "| agent | coverage | bits per metre |",
        "|---|---|---|",
    ]
    ref_cov = np.array([by[("frontier", s)]["coverage"] for s in seeds])
    ref_bpm = np.array([by[("frontier", s)]["bits_per_m"] for s in seeds])
    for label in AGENTS:
        if label == "frontier":
            continue
        cov = np.array([by[(label, s)]["coverage"] for s in seeds])
        bpm = np.array([by[(label, s)]["bits_per_m"] for s in seeds])
        lines.append(
            f"| {label} | {compare_paired(ref_cov, cov, ratio=True).text('{:.3f}')} | "
            f"{compare_paired(ref_bpm, bpm, ratio=True).text('{:.3f}')} |"
        )
    lines.append("")
    lines.append("† privileged: reads the true plan and pose.")
    return "\n".join(lines)


if __name__ == "__main__":
    main()
