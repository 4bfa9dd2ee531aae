"""A ranking you can trust (issue 51, item 3): each gain model's rank correlation with the bits a
candidate's path truly buys.

Drives ``rollout-explore`` on validation seeds; at every ``--every``-th decision it takes the
best ``ranked_candidates`` (16) of its menu by expected bits per metre and scores each by:
today's expected bits per metre (``predicted_gain`` over the path's cost), the dry run of the
mapper's update along its first 20 readings with k from the belief's walls, and the same with k
from the predicted map's walls (each as the 20 readings' total and as the best-prefix rate).
The truth is what the env's mapper gains along those readings from the true radio
(``true_path_bits``: the rollout oracle's). Prints the mean Spearman correlation per decision
with a 95 % interval.

    python scripts/studies/ranking_study.py --episodes 5 --out runs/ranking
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np
from scipy.stats import spearmanr

import sfw_gym  # noqa: F401  (registers the ids)
from sfw_gym.agents.rollout_explore import true_path_bits
from sfw_gym.evaluation.benchmark import load_protocol, split_seeds
from sfw_gym.evaluation.stats import mean_ci95
from sfw_gym.mapping.dry_run import DryRun
from sfw_gym.mapping.grid import belief_classes
from sfw_gym.navigation.path_gain import best_prefix_rate, path_totals, walls_crossed
from sfw_gym.rl.predict_explore import RolloutExploreAgent

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from _docs import RESULTS, write_block

MODELS = (
    "expected bits per metre (today's)",
    "dry run, belief walls: total",
    "dry run, belief walls: best-prefix rate",
    "dry run, predicted walls: total",
    "dry run, predicted walls: best-prefix rate",
)


class Probe(RolloutExploreAgent):
    """rollout-explore that also scores its top candidates by every model and by the truth."""

    def __init__(self, env, every: int, **kw) -> None:
        super().__init__(**kw)
        self.env, self.every, self.rows, self.n_picks = env, every, [], 0

    def _pick(self, view, paths, targets, goals, score):
        self.n_picks += 1
        top = self.top_candidates(score)
        if self.n_picks % self.every == 0 and len(top) >= 4:
            xy, starts = self.readings(view, paths, goals[top])
            grid = view.grid
            router = self.reading_routers(view, xy)
            dry = DryRun.of_view(view)
            scores = {MODELS[0]: score[top]}
            for walls, label in (
                (belief_classes(view.belief_u8)[1], "belief walls"),
                (self.prediction(view).p_wall >= 0.5, "predicted walls"),
            ):
                k = walls_crossed(grid, walls, view.routers_xy, router, xy)
                g = dry.path_gains(xy, router, k, starts)
                scores[f"dry run, {label}: total"] = path_totals(g, starts)
                scores[f"dry run, {label}: best-prefix rate"] = best_prefix_rate(
                    g, starts, self.settings.min_prefix_steps
                )
            truth = path_totals(
                true_path_bits(self.env.unwrapped, xy, starts, np.random.default_rng(0)), starts
            )
            row = {"step": self.steps, "truth": truth.tolist()}
            for m in MODELS:
                row[m] = float(spearmanr(scores[m], truth).statistic)
            row["regret"] = {
                m: float(truth.max() - truth[int(np.argmax(scores[m]))]) for m in MODELS
            }
            row["truth_max"] = float(truth.max())
            self.rows.append(row)
        return super()._pick(view, paths, targets, goals, score)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--episodes", type=int, default=5)
    p.add_argument("--max-steps", type=int, default=3000)
    p.add_argument("--every", type=int, default=5, help="score every n-th decision")
    p.add_argument("--out", default="runs/ranking")
    p.add_argument("--write-docs", action="store_true")
    args = p.parse_args()
    first, _ = split_seeds(load_protocol(), "validation")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for seed in range(first, first + args.episodes):
        path = out / f"{seed}.json"
        if not path.exists():
            env = gym.make("SfW-Explore-v0", max_steps=args.max_steps)
            obs, _ = env.reset(seed=seed)
            agent = Probe(env, args.every)
            agent.reset(env, seed=seed)
            done = False
            while not done:
                obs, _, terminated, truncated, _ = env.step(agent.act(obs))
                done = terminated or truncated
            path.write_text(json.dumps(agent.rows))
        rows += [r for r in json.loads(path.read_text()) if np.isfinite(r[MODELS[0]])]
    cmd = f"python scripts/studies/ranking_study.py --episodes {args.episodes} --out {args.out}"
    lines = [
        f"`{cmd}`: {len(rows)} decisions of rollout-explore on validation seeds "
        f"{first:,}-{first + args.episodes - 1:,}, the best 16 candidates of each; Spearman "
        "correlation with the bits the first 20 readings truly buy (mean over decisions, 95 % "
        "interval), and the bits per decision lost against the best candidate:",
        "",
        "| gain model | Spearman | bits lost (of the best's) |",
        "|---|---|---|",
    ]
    best = np.mean([r["truth_max"] for r in rows])
    for m in MODELS:
        rho = [r[m] for r in rows if np.isfinite(r[m])]
        mean, half, _ = mean_ci95(rho)
        lost = np.mean([r["regret"][m] for r in rows])
        lines.append(f"| {m} | {mean:.2f} ± {half:.2f} | {lost:.2f} ({lost / best:.0%}) |")
    text = "\n".join(lines)
    print(text)
    if args.write_docs:
        write_block(RESULTS / "rollout.md", "ranking_study", text.splitlines())


if __name__ == "__main__":
    main()
