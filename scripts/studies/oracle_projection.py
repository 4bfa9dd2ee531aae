"""What a region policy could take from the coverage oracle (issue 40, item 3's first question).

A region policy chooses among the navigation menu's candidates every 20 steps, so it could
only ever be taught the coverage oracle's intent projected onto that menu. Here a privileged
region agent does exactly that. At each decision it takes the coverage oracle's current target,
kept in step with the robot, and chooses the valid candidate whose target cell lies nearest to
it. The region steering drives as usual. Each episode runs to the longest budget. At every
budget the script prints bits per metre and coverage as ratios to frontier's, paired by seed
(95 % bootstrap). If the projection keeps the oracle's gain, distilling it is worth a training
run; if it does not, no region policy can learn it.

    python scripts/studies/oracle_projection.py --seeds 5 --budgets 1000,3000,10000
"""

from __future__ import annotations

import argparse
from typing import Any

import gymnasium as gym
import numpy as np

import sfw_gym  # noqa: F401  (registers the ids)
from sfw_gym.agents import make_agent
from sfw_gym.agents.base import Agent, RobotView
from sfw_gym.agents.coverage_oracle import CoverageOracle
from sfw_gym.agents.oracles import OracleAgent
from sfw_gym.agents.regions import RegionAgent
from sfw_gym.evaluation.stats import compare_paired
from sfw_gym.navigation.candidates import CandidateGoals


class ProjectedOracle(OracleAgent, RegionAgent):
    """Region choices: the valid candidate nearest the coverage oracle's target (privileged)."""

    name = "oracle-projected"

    def _on_reset(self, view: RobotView) -> None:
        super()._on_reset(view)
        self.tour = CoverageOracle()
        self.tour.reset(self._env, seed=0)

    def _act(self, view: RobotView, obs: Any) -> tuple[float, float]:
        self.tour.act(obs)  # its visited cells and replans follow the robot; its command is unused
        return super()._act(view, obs)

    def choose(
        self, view: RobotView, obs: Any, menu: CandidateGoals, extra: dict[str, np.ndarray]
    ) -> int:
        self.tour.plan(view, self.ground_truth().pose)
        valid = np.flatnonzero(menu.valid[: self.config.max_candidates])
        if self.tour.target_rc is None or not len(valid):
            return super().choose(view, obs, menu, extra)
        offsets = menu.target_rc[valid] - np.asarray(self.tour.target_rc)
        return int(valid[np.argmin(np.hypot(offsets[:, 0], offsets[:, 1]))])


def run(agent: Agent, seed: int, budgets: list[int]) -> dict[int, tuple[float, float]]:
    """(bits per metre, coverage) at each budget of one episode of ``max(budgets)`` steps (an
    episode that ended earlier keeps its final figures)."""
    env = gym.make("SfW-Explore-v0", max_steps=max(budgets))
    obs, info = env.reset(seed=seed)
    start = info["entropy_bits"]
    agent.reset(env, seed=seed)
    out, steps, done = {}, 0, False
    while not done:
        obs, _, terminated, truncated, info = env.step(agent.act(obs))
        steps += 1
        done = terminated or truncated
        for b in budgets:
            if b not in out and (steps == b or done):
                bits = (start - info["entropy_bits"]) / max(info["path_length_m"], 1e-9)
                out[b] = (bits, info["coverage"])
    return out


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--seeds", type=int, default=10, help="benchmark-v1 test seeds from 2000000")
    p.add_argument("--budgets", default="3000,10000")
    args = p.parse_args()
    budgets = sorted(int(b) for b in args.budgets.split(","))
    names = ("frontier", "oracle-coverage", "oracle-projected")
    results: dict[str, list[dict[int, tuple[float, float]]]] = {n: [] for n in names}
    for seed in range(2_000_000, 2_000_000 + args.seeds):
        for name in names:
            agent = ProjectedOracle() if name == "oracle-projected" else make_agent(name)
            results[name].append(run(agent, seed, budgets))
        print(f"seed {seed} done", flush=True)
    print(f"\n{args.seeds} test seeds; ratio of means to frontier [95 % paired bootstrap]\n")
    print("| agent | budget | bits/m | bits/m ratio | coverage | coverage ratio |")
    print("|---|---:|---:|---|---:|---|")
    for b in budgets:
        ref = np.array([r[b] for r in results["frontier"]])
        for name in names:
            x = np.array([r[b] for r in results[name]])
            bits = compare_paired(ref[:, 0], x[:, 0], ratio=True).text("{:.3f}")
            cov = compare_paired(ref[:, 1], x[:, 1], ratio=True).text("{:.3f}")
            label = name + (" †" if name.startswith("oracle") else "")
            print(
                f"| {label} | {b:,} | {x[:, 0].mean():.1f} | {bits} | {x[:, 1].mean():.3f} "
                f"| {cov} |"
            )


if __name__ == "__main__":
    main()
