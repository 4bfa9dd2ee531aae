"""Train the map predictor (issue 46) on the snapshots of ``collect_snapshots.py``; checkpoints
every 500 steps and resumes when run again with the same ``--out``.

    python scripts/tools/train_predictor.py --snapshots runs/predictor/snapshots \
        --out runs/predictor/model --steps 10000 --threads 1
    python scripts/tools/train_predictor.py --out runs/predictor/model --steps 10000 --threads 1 \
        --export      # stopped early: its latest checkpoint as the model
    cp runs/predictor/model/{model.pt,config.json} sfw_gym/data/agents/predictor/   # ship it
"""

from __future__ import annotations

import argparse
from pathlib import Path

from sfw_gym.evaluation.prediction import load_snapshots
from sfw_gym.rl.map_predictor import (
    PredictorConfig,
    PredictorTraining,
    export_checkpoint,
    train_predictor,
)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--snapshots", default="runs/predictor/snapshots", help="a folder of .npz")
    p.add_argument("--out", default="runs/predictor/model")
    defaults = PredictorTraining()
    p.add_argument("--steps", type=int, default=defaults.steps)
    p.add_argument("--batch", type=int, default=defaults.batch)
    p.add_argument("--crop", type=int, default=defaults.crop)
    p.add_argument("--lr", type=float, default=defaults.lr)
    p.add_argument("--threads", type=int, default=defaults.threads)
    p.add_argument("--seed", type=int, default=defaults.seed)
    p.add_argument("--width", type=int, default=PredictorConfig().width)
    p.add_argument("--heads", type=int, default=PredictorConfig().heads)
    p.add_argument(
        "--export",
        action="store_true",
        help="write the latest checkpoint of --out as the model (a run stopped early), no training",
    )
    args = p.parse_args()
    files = sorted(Path(args.snapshots).glob("*.npz"))
    training = PredictorTraining(
        steps=args.steps,
        batch=args.batch,
        crop=args.crop,
        lr=args.lr,
        seed=args.seed,
        threads=args.threads,
    )
    network = PredictorConfig(args.width, args.heads)
    episodes = [load_snapshots(f) for f in files]
    if args.export:
        export_checkpoint(episodes, args.out, training, network)
        print(f"{args.out}: exported its checkpoint")
        return
    out = train_predictor(episodes, args.out, training, network, checkpoint_every=500)
    print(f"{out}: trained on {len(files)} episodes")


if __name__ == "__main__":
    main()
