"""Collect (belief snapshot, true plan) pairs for the map predictor (issue 46), on the native
vector env: episodes of several agents on the benchmark's train seeds, a snapshot every
``--every`` steps, one ``.npz`` per episode (resumes: episodes already written are skipped).

    python scripts/tools/collect_snapshots.py --episodes 800 --out runs/predictor/snapshots
    python scripts/tools/collect_snapshots.py --agents frontier --episodes 50 --seed 2000000 \
        --steps 750,1500,2250 --out runs/predictor/test_snapshots     # the quality table's
"""

from __future__ import annotations

import argparse

from tqdm import tqdm

from sfw_gym.evaluation.prediction import SnapshotEpisode, collect_snapshots

#: The agents whose states the predictor learns from, and their shares of the episodes.
DEFAULT_MIX = "frontier:0.4,greedy:0.2,cross-pass:0.15,random:0.15,regions-ppo:0.1"


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--agents", default=DEFAULT_MIX, help="name:share,... (default: %(default)s)")
    p.add_argument("--episodes", type=int, default=800)
    p.add_argument("--seed", type=int, default=0, help="first env seed (train split: 0-999999)")
    p.add_argument("--every", type=int, default=25, help="steps between snapshots")
    p.add_argument("--max-steps", type=int, default=3000)
    p.add_argument("--steps", default="", help="comma-separated snapshot steps (overrides --every)")
    p.add_argument("--floorplans", default=None, help="a folder of plan files instead of seeds")
    p.add_argument("--num-envs", type=int, default=8)
    p.add_argument("--shard", default="0/1", help="k/n: this process's share of the episodes")
    p.add_argument("--out", default="runs/predictor/snapshots")
    args = p.parse_args()

    steps = (
        tuple(int(s) for s in args.steps.split(","))
        if args.steps
        else tuple(range(args.every, args.max_steps + 1, args.every))
    )
    mix = [
        (name, float(share or 1))
        for name, _, share in (a.partition(":") for a in args.agents.split(","))
    ]
    plans: list[str | None] = [None]
    if args.floorplans:
        from pathlib import Path

        plans = [str(f) for f in sorted(Path(args.floorplans).glob("*.json"))]
    total = sum(share for _, share in mix)
    episodes, i = [], 0
    for name, share in mix:
        for _ in range(round(args.episodes * share / total)):
            plan = plans[i % len(plans)]
            episodes.append(SnapshotEpisode(name, args.seed + i, steps, plan))
            i += 1
    k, n = (int(x) for x in args.shard.split("/"))
    mine = episodes[k::n]
    with tqdm(total=len(mine), desc="episodes") as bar:
        collect_snapshots(mine, args.out, num_envs=args.num_envs, progress=bar.update)


if __name__ == "__main__":
    main()
