"""PPO on the wheels: held-out return and coverage against env steps, several training seeds,
with random actions', random waypoints' and frontier's levels drawn in (rl-zoo's benchmark plots).

    python scripts/figures/plot_wheels_curve.py RUN [RUN ...] [--episodes 5] [--seed 1000000]
        [--stride 1] [--out docs/figures/wheels_ppo_curve.png] [--write-docs]

Each RUN is a ``sfw-gym train ppo --env SfW-Explore-v0`` output folder (one training seed). Every
checkpoint in ``RUN/checkpoints`` is evaluated, its policy deterministic, on the same held-out
validation plans (env seeds ``--seed`` + i, never trained on), the episodes stepped together on
the native vector env; the figures are cached in ``RUN/heldout.csv`` so that a rerun evaluates
only new checkpoints. The levels are measured on the same plans. Printed: per seed, the mean of
the first and of the last tenth of the evaluations with 95 % t-intervals over their episodes,
the run's steps per second and wall time from its ``config.yml``, and the PPO diagnostics of
its TensorBoard log; ``--write-docs`` writes these tables into docs/results/training.md.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import re
import sys
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import yaml

import sfw_gym  # noqa: F401  (registration)
from sfw_gym.evaluation.stats import mean_ci95
from sfw_gym.rl.training import native_action_repeat, wrapper_specs

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))  # _docs
from _docs import command_line, write_block

ENV_ID = "SfW-Explore-v0"
COLUMNS = ("steps", "episode", "return", "coverage")
#: What SB3 logs per PPO update (and sfw-gym train per head), in the diagnostics table.
DIAGNOSTICS = (
    "train/explained_variance",
    "train/entropy_loss",
    "train/std",
    "train/approx_kl",
    "train/clip_fraction",
    "train/grad_norm_features",
    "train/grad_norm_actor",
    "train/grad_norm_critic",
)


def evaluate_vector(act, episodes: int, seed: int, env_kwargs: dict) -> tuple[np.ndarray, ...]:
    """Return and final coverage of ``episodes`` episodes (env seeds ``seed`` + i) stepped
    together; ``act(obs)`` maps the batched observation to the batch of actions."""
    venv = gym.make_vec(
        ENV_ID, num_envs=episodes, vectorization_mode="vector_entry_point", **env_kwargs
    )
    obs, _ = venv.reset(seed=[seed + i for i in range(episodes)])
    returns, coverage = np.zeros(episodes), np.zeros(episodes)
    done = np.zeros(episodes, bool)
    while not done.all():
        obs, reward, terminated, truncated, info = venv.step(act(obs))
        returns += np.where(done, 0.0, reward)
        ended = (terminated | truncated) & ~done
        coverage[ended] = np.asarray(info["coverage"])[ended]
        done |= ended
    venv.close()
    return returns, coverage


def policy_act(model_path: Path, repeat: int = 1):
    """The deterministic policy of a checkpoint as a batched ``act(obs)``, deciding every
    ``repeat`` calls and holding its actions in between (the run's ActionRepeat)."""
    from stable_baselines3 import PPO

    model = PPO.load(model_path, device="cpu")
    held: dict[str, Any] = {"calls": 0, "actions": None}

    def act(obs: dict[str, np.ndarray]) -> np.ndarray:
        if held["calls"] % repeat == 0:
            held["actions"] = model.predict(obs, deterministic=True)[0]
        held["calls"] += 1
        return held["actions"]

    return act


def run_repeat(config: dict[str, Any]) -> int:
    """The action repeat a run was trained with (1: none)."""
    wrappers = wrapper_specs(config.get("hyperparameters", {}).get("env_wrapper"))
    return native_action_repeat(wrappers) or 1


def every_nth(checkpoints: list[Any], stride: int) -> list[Any]:
    """Every ``stride``-th of the checkpoints counted back from the last, and the first (where
    the curve starts), in order."""
    chosen = checkpoints[::-1][::stride][::-1]
    return checkpoints[:1] + chosen if chosen[:1] != checkpoints[:1] else chosen


def evaluate_run(run: Path, episodes: int, seed: int, stride: int = 1) -> list[dict[str, float]]:
    """The checkpoints of ``run`` that :func:`every_nth` picks, on the held-out plans (cached in
    ``run/heldout.csv``)."""
    cache = run / "heldout.csv"
    rows: list[dict[str, float]] = []
    if cache.is_file():
        with cache.open(encoding="utf-8") as fh:
            rows = [{k: float(v) for k, v in row.items()} for row in csv.DictReader(fh)]
        if {int(r["episode"]) for r in rows} != set(range(episodes)):
            rows = []  # another size: evaluate again
    done = {int(r["steps"]) for r in rows}
    checkpoints = sorted(
        (int(m.group(1)), path)
        for path in (run / "checkpoints").glob("ppo_*_steps.zip")
        if (m := re.fullmatch(r"ppo_(\d+)_steps\.zip", path.name))
    )
    config = yaml.safe_load((run / "config.yml").read_text(encoding="utf-8"))
    repeat = run_repeat(config)
    for decisions, path in every_nth(checkpoints, stride):
        steps = decisions * repeat  # env steps
        if steps in done:
            continue
        returns, coverage = evaluate_vector(policy_act(path, repeat), episodes, seed, {})
        rows += [
            {"steps": steps, "episode": i, "return": returns[i], "coverage": coverage[i]}
            for i in range(episodes)
        ]
        print(
            f"{run.name} {steps:>9,} steps: return {returns.mean():6.2f}, "
            f"coverage {coverage.mean():.3f}",
            flush=True,
        )
        with cache.open("w", encoding="utf-8", newline="") as fh:
            writer = csv.DictWriter(fh, fieldnames=COLUMNS)
            writer.writeheader()
            writer.writerows(sorted(rows, key=lambda r: (r["steps"], r["episode"])))
    return sorted(rows, key=lambda r: (r["steps"], r["episode"]))


def reference_levels(episodes: int, seed: int) -> dict[str, dict[str, float]]:
    """Random actions', random waypoints' and frontier's mean return and coverage on the plans."""
    from sfw_gym.agents import make_agent
    from sfw_gym.envs.waypoint import WaypointWrapper

    levels = {}
    rng = np.random.default_rng(seed)
    ret, cov = evaluate_vector(
        lambda obs: rng.uniform(-1, 1, (episodes, 2)).astype(np.float32), episodes, seed, {}
    )
    levels["random actions"] = {"return": ret.mean(), "coverage": cov.mean()}
    for name in ("random waypoints", "frontier"):
        ret, cov = np.zeros(episodes), np.zeros(episodes)
        for i in range(episodes):
            env = gym.make(ENV_ID)
            if name == "random waypoints":
                env = WaypointWrapper(env)
                env.action_space.seed(seed + i)
            obs, info = env.reset(seed=seed + i)
            agent = make_agent("frontier") if name == "frontier" else None
            if agent is not None:
                agent.reset(env, seed=seed + i)
            done = False
            while not done:
                action = agent.act(obs) if agent is not None else env.action_space.sample()
                obs, reward, terminated, truncated, info = env.step(action)
                ret[i] += float(reward)
                done = terminated or truncated
            cov[i] = info["coverage"]
            env.close()
        levels[name] = {"return": ret.mean(), "coverage": cov.mean()}
    return {k: {m: float(v) for m, v in d.items()} for k, d in levels.items()}


def tenths(rows: list[dict[str, float]], metric: str) -> tuple[tuple, tuple]:
    """Mean and 95 % interval over the episodes of the first and of the last tenth of the
    evaluations (at least one evaluation each)."""
    steps = sorted({r["steps"] for r in rows})
    k = max(1, math.ceil(len(steps) / 10))
    first = [r[metric] for r in rows if r["steps"] in steps[:k]]
    last = [r[metric] for r in rows if r["steps"] in steps[-k:]]
    return tuple(_interval(values) for values in (first, last))  # type: ignore[return-value]


def _interval(values: list[float]) -> tuple[float, float, float]:
    mean, half, _ = mean_ci95(values)
    return mean, mean - half, mean + half


def training_diagnostics(run: Path) -> list[str]:
    """Markdown rows: each of :data:`DIAGNOSTICS` averaged over the first, middle and last
    tenth of the run's PPO updates (from its TensorBoard log)."""
    from tensorboard.backend.event_processing.event_accumulator import EventAccumulator

    rows = []
    for folder in sorted((run / "tb").glob("*")):
        events = EventAccumulator(str(folder))
        events.Reload()
        for tag in DIAGNOSTICS:
            if tag not in events.Tags()["scalars"]:
                continue
            values = np.array([e.value for e in events.Scalars(tag)])
            k, n = max(1, len(values) // 10), len(values)
            parts = (values[:k], values[n // 2 - k // 2 : n // 2 - k // 2 + k], values[-k:])
            cells = " | ".join(f"{part.mean():.4g}" for part in parts)
            rows.append(f"| {run.name} | {tag.removeprefix('train/')} | {cells} |")
    return rows


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("runs", type=Path, nargs="+")
    p.add_argument("--episodes", type=int, default=5)
    p.add_argument("--seed", type=int, default=1_000_000, help="first held-out env seed")
    p.add_argument(
        "--stride", type=int, default=1, help="every STRIDE-th checkpoint (from the last)"
    )
    p.add_argument("--out", type=Path, default=Path("docs/figures/wheels_ppo_curve.png"))
    p.add_argument("--write-docs", action="store_true", help="the tables into training.md")
    args = p.parse_args()
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    runs = {run: evaluate_run(run, args.episodes, args.seed, args.stride) for run in args.runs}
    levels_file = args.runs[0].parent / f"levels_{args.seed}_{args.episodes}.json"
    if levels_file.is_file():
        levels = json.loads(levels_file.read_text(encoding="utf-8"))
    else:
        levels = reference_levels(args.episodes, args.seed)
        levels_file.write_text(json.dumps(levels, indent=1), encoding="utf-8")

    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    rose = ["| seed | metric | first tenth | last tenth | rose |", "|---|---|---|---|---|"]
    times = ["| seed | env steps (decisions) | wall time | env steps/s |", "|---|---|---|---|"]
    for run, rows in runs.items():
        config = yaml.safe_load((run / "config.yml").read_text(encoding="utf-8"))
        steps = np.array(sorted({r["steps"] for r in rows}))
        for ax, metric in zip(axes, ("return", "coverage"), strict=True):
            mean = [np.mean([r[metric] for r in rows if r["steps"] == s]) for s in steps]
            ax.plot(steps, mean, marker=".", label=f"seed {config.get('seed')}")
            (m0, lo0, hi0), (m1, lo1, hi1) = tenths(rows, metric)
            rose.append(
                f"| {config.get('seed')} | {metric} | {m0:.3f} [{lo0:.3f}, {hi0:.3f}] | "
                f"{m1:.3f} [{lo1:.3f}, {hi1:.3f}] | {'yes' if lo1 > hi0 else 'no'} |"
            )
        wall = float(config.get("total_wall_time_s") or config.get("wall_time_s") or 0.0)
        env_steps = config["steps"] * run_repeat(config)
        times.append(
            f"| {config.get('seed')} | {env_steps:,} ({config['steps']:,}) | {wall / 60:.0f} min "
            f"| {env_steps / max(wall, 1e-9):,.0f} |"
        )
    for ax, metric in zip(axes, ("return", "coverage"), strict=True):
        for (name, level), style in zip(levels.items(), (":", "--", "-."), strict=True):
            ax.axhline(level[metric], color="grey", linestyle=style, label=name)
        ax.set_xlabel("env steps")
        ax.set_ylabel(f"held-out {metric} (deterministic, {args.episodes} plans)")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle(f"PPO on the wheels of {ENV_ID}, from scratch")
    fig.tight_layout()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=110)
    diagnostics = [
        "| run | logged per update | first tenth | middle tenth | last tenth |",
        "|---|---|---:|---:|---:|",
        *(row for run in runs for row in training_diagnostics(run)),
    ]
    level_rows = ["| level | return | coverage |", "|---|---:|---:|"] + [
        f"| {name} | {level['return']:.2f} | {level['coverage']:.3f} |"
        for name, level in levels.items()
    ]
    blocks = {
        "wheels_curve": [f"`{command_line()}`:", "", *rose, "", *level_rows],
        "wheels_time": times,
        "wheels_diagnostics": diagnostics,
    }
    for lines in blocks.values():
        print("\n".join(lines) + "\n")
    if args.write_docs:
        page = Path(__file__).resolve().parents[2] / "docs" / "results" / "training.md"
        for name, lines in blocks.items():
            write_block(page, name, lines)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
