"""PPO on the wheels against frontier and random actions, paired on the same plans and seeds.

    python scripts/studies/wheels_study.py --episodes 50 --seed 2000000 --out runs/wheels_test \
        --write-docs wheels_test
    python scripts/studies/wheels_study.py --episodes 11 \
        --floorplans ../shared/floorplans/houseexpo --out runs/wheels_hx --write-docs wheels_hx
    python scripts/studies/wheels_study.py --model runs/wheels_s1 --episodes 10 \
        --seed 1000000 --out runs/wheels_val      # a run of one's own, on validation seeds

Runs ``sfw-gym evaluate`` (resuming what is done) with frontier, ``wheels-ppo`` deterministic
(its default) and sampled, and random actions (a new uniform action every step), each episode
on the env's defaults (3,000 steps). Prints per agent the mean coverage and return (the env's
own reward: 0.01 per bit less 0.1 per contact step, recomputed from the record), the geometric
mean of the per-plan coverage ratios to frontier's, and the return's paired difference from
random actions', each with a 95 % paired bootstrap interval (the package's ``bootstrap_ci``).
``--write-docs NAME`` writes the table into the block NAME of docs/results/training.md.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from sfw_gym.envs.config import RewardConfig
from sfw_gym.evaluation.runner import evaluate
from sfw_gym.evaluation.stats import bootstrap_ci

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))  # _docs
from _docs import command_line, write_block

WHEELS = "sfw_gym.rl.wheels_agent:WheelsPPOAgent"
#: The rows: label → (agent name or entry point, parameters).
AGENTS = {
    "frontier": ("frontier", {}),
    "wheels-ppo (deterministic)": ("wheels-ppo", {}),
    "wheels-ppo (sampled)": (WHEELS, {"deterministic": False}),
    "random actions": ("random", {"hold_steps": 1}),
}


def episode_return(record: dict, reward_scale: float, collision_penalty: float) -> float:
    """The env's return of an episode from its record: the bits it mapped and its contact
    steps (``reward = reward_scale · bits − collision_penalty · bumped``, summed)."""
    return reward_scale * record["info_gain_total_bits"] - collision_penalty * record["collisions"]


def geometric_mean_ratio(reference: np.ndarray, other: np.ndarray) -> tuple[float, float, float]:
    """The geometric mean of ``other / reference`` per plan, with the bootstrap interval of the
    mean log ratio taken back (plans where either is 0 are left out)."""
    keep = (reference > 0) & (other > 0)
    logs = np.log(other[keep] / reference[keep])
    low, high = bootstrap_ci(logs)
    return float(np.exp(logs.mean())), float(np.exp(low)), float(np.exp(high))


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--episodes", type=int, default=50)
    p.add_argument("--seed", type=int, default=2_000_000, help="benchmark-v1's test seeds")
    p.add_argument("--floorplans", default=None)
    p.add_argument("--model", default=None, help="wheels-ppo's model folder (default: shipped)")
    p.add_argument("--out", default="runs/wheels_study")
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--write-docs", default=None, metavar="BLOCK", help="training.md's block")
    args = p.parse_args()

    names, params = [], {}
    for name, kwargs in AGENTS.values():
        names.append(name)
        wheels = name in ("wheels-ppo", WHEELS)
        params[name] = dict(kwargs) | ({"path": args.model} if args.model and wheels else {})
    result = evaluate(
        names, args.episodes, args.seed, out=args.out, floorplans=args.floorplans,
        agent_params=params, workers=args.workers, progress=False,
    )  # fmt: skip
    defaults = RewardConfig()
    records: dict[str, dict[int, dict]] = {}
    for r in result["records"]:
        records.setdefault(r["agent"], {})[r["episode"]] = r
    episodes = sorted(set.intersection(*(set(v) for v in records.values())))

    def column(name: str, key: str) -> np.ndarray:
        rows = [records[name][i] for i in episodes]
        if key == "return":
            return np.array(
                [episode_return(r, defaults.reward_scale, defaults.collision_penalty) for r in rows]
            )
        return np.array([float(r[key]) for r in rows])

    frontier, rand = column("frontier", "coverage"), column("random", "return")
    lines = [
        f"{len(episodes)} paired episodes (seed {args.seed}"
        + (f", plans {args.floorplans}" if args.floorplans else "")
        + ")",
        "",
        "| agent | coverage | coverage ÷ frontier (geometric mean, 95 % CI) | return "
        "| return − random actions' (95 % CI) | contact steps |",
        "|---|---:|---|---:|---|---:|",
    ]
    summary = {}
    for label, (name, _) in AGENTS.items():
        cov, ret = column(name, "coverage"), column(name, "return")
        ratio = geometric_mean_ratio(frontier, cov)
        diff = ret - rand
        low, high = bootstrap_ci(diff)
        summary[label] = {
            "coverage": float(cov.mean()), "coverage_ratio": ratio, "return": float(ret.mean()),
            "return_minus_random": (float(diff.mean()), low, high),
        }  # fmt: skip
        lines.append(
            f"| {label} | {cov.mean():.3f} | {ratio[0]:.3f} [{ratio[1]:.3f}, {ratio[2]:.3f}] | "
            f"{ret.mean():.2f} | {diff.mean():+.2f} [{low:+.2f}, {high:+.2f}] | "
            f"{column(name, 'collisions').mean():.0f} |"
        )
    text = "\n".join(lines)
    if args.write_docs:
        page = Path(__file__).resolve().parents[2] / "docs" / "results" / "training.md"
        write_block(page, args.write_docs, [f"`{command_line()}`:", "", *lines])
    Path(args.out, "wheels.md").write_text(text + "\n", encoding="utf-8")
    Path(args.out, "wheels.json").write_text(json.dumps(summary, indent=1), encoding="utf-8")
    print(text)


if __name__ == "__main__":
    main()
