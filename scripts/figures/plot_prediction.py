"""The map predictor at work (issue 46): at a few moments of one ``predict-explore`` episode, the
belief, the predicted map and the true plan side by side, with the robot's path so far.

    python scripts/figures/plot_prediction.py --seed 2000003

The predicted map is drawn as colour: green where it expects free space, red where it expects a
wall, dark where it expects neither (outside); the believed cells in grey (free light, walls
black). docs/results/prediction.md shows it.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import gymnasium as gym
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import sfw_gym  # noqa: F401 (registration)
from sfw_gym.agents import make_agent
from sfw_gym.navigation.prediction import FREE, WALL, belief_class


def predicted_rgb(p_free: np.ndarray, p_wall: np.ndarray) -> np.ndarray:
    """Green for expected free space, red for an expected wall (brightness: the probability)."""
    return np.stack([p_wall, p_free, 0.15 * np.ones_like(p_free)], axis=-1).clip(0, 1)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--seed", type=int, default=2_000_003, help="a test-split plan")
    p.add_argument("--moments", default="500,1500,2500", help="steps at which to draw")
    p.add_argument("--model", default=None, help="a predictor folder (default: the shipped one)")
    p.add_argument("--out", default="docs/figures/prediction_moments.png")
    args = p.parse_args()
    moments = [int(m) for m in args.moments.split(",")]
    env = gym.make("SfW-Explore-v0")
    obs, _ = env.reset(seed=args.seed)
    agent = make_agent("predict-explore", **({"path": args.model} if args.model else {}))
    agent.reset(env, seed=args.seed)
    shots = []
    for step in range(1, max(moments) + 1):
        obs, _, terminated, truncated, _ = env.step(agent.act(obs))
        if step in moments:
            view = env.unwrapped.robot_view()
            predicted = agent.prediction(view)
            shots.append((step, view.belief_u8.copy(), predicted, view.odometry_trajectory.copy()))
        if terminated or truncated:
            break
    truth = env.unwrapped.ground_truth()
    grid = truth.grid
    fig, axes = plt.subplots(len(shots), 3, figsize=(10, 3.2 * len(shots)), squeeze=False)
    for row, (step, belief, predicted, traj) in zip(axes, shots, strict=True):
        cls = belief_class(belief)
        shown = np.full(cls.shape, 0.5)
        shown[cls == FREE], shown[cls == WALL] = 1.0, 0.0
        rc = grid.world_to_cell(traj)
        panels = [
            (shown, "gray", f"belief at step {step:,}"),
            (
                predicted_rgb(predicted.p_free, predicted.p_wall),
                None,
                "predicted: green free, red wall",
            ),
            (truth.truth_u8, "gray", "true plan"),
        ]
        for ax, (image, cmap, title) in zip(row, panels, strict=True):
            ax.imshow(image, cmap=cmap, origin="lower", interpolation="nearest")
            ax.plot(rc[:, 1], rc[:, 0], color="tab:blue", lw=0.6)
            ax.set_title(title, fontsize=9)
            ax.set_xticks([])
            ax.set_yticks([])
    fig.suptitle(f"predict-explore on test plan {args.seed}", fontsize=10)
    fig.tight_layout()
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=110)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
