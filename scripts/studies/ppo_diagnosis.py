"""Why PPO stayed flat on SfW-Explore-v0: the standard checks, on the env's own actions (issue 50).

    nice -n 15 python scripts/studies/ppo_diagnosis.py [--ids SfW-Explore-v0,SfW-ExploreDiscrete-v0,
        SfW-ExploreSmall-v0] [--episodes 5] [--behaviours frontier,cross-pass,...]
        [--waypoint-episodes 3] [--out runs/diagnosis]

Five measurements, written to ``OUT/diagnosis.md`` (the tables printed here) and
``OUT/diagnosis.json`` (every number):

1. **Ranking**: the env's default reward's ranking of known behaviours per explore id, paired on
   the validation seeds 1,000,000 + i: the registered agents (frontier, cross-pass, greedy) and
   scripted ones on raw actions (random actions, driving straight, spinning in place, a bump-driven
   wall follower). Per behaviour the episode return with its 95 % t-interval, the final coverage,
   the return's two parts (reward_scale × bits gained, collision_penalty × bumps) and the rank.
2. **Variance**: a two-way decomposition (behaviours × plans, no interaction) of the paired
   returns, and the signal-to-noise of a difference between two behaviours: its mean ÷ the
   return's spread across plans (no baseline) and ÷ the paired differences' spread (a critic
   that knew the plan).
3. **Reward scale and horizon**: per-step reward statistics of random actions and frontier, the
   effective horizon 1 / (1 − γ) in steps and metres, frontier's bits earned beyond it, and how the
   discounted return-to-go relates to the undiscounted one.
4. **VecNormalize**: the spread of the discounted return (γ = 0.99) that VecNormalize divides
   the reward by, and the per-step reward once divided (its running statistics taken as converged).
5. **The waypoint policy** (``sfw_gym/data/agents/ppo/SfW-Explore-v0_1``): its monitor log's first
   vs last 300 episodes, the per-waypoint reward's spread between plans against the difference
   to random waypoints, its action distribution's entropy against uniform over the 64 blocks,
   its deterministic mode's distinct blocks; and the first attempt's architecture (SB3's
   NatureCNN on the 64 × 64 map image): metres per pixel on these plans, the first layer's
   footprint, its parameter count and feature shapes. No training.

The default run (5 episodes on 3 ids, 3 waypoint episodes per mode) costs about 3.5 min of CPU.
"""

from __future__ import annotations

import argparse
import json
import math
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

import sfw_gym  # noqa: F401  (registration)
from sfw_gym.core.errors import ConfigError
from sfw_gym.evaluation.stats import mean_ci95, mean_ci95_text

SEED0 = 1_000_000  # the validation seeds
DEFAULT_IDS = ("SfW-Explore-v0", "SfW-ExploreDiscrete-v0", "SfW-ExploreSmall-v0")
AGENT_BEHAVIOURS = ("frontier", "cross-pass", "greedy")
SCRIPTED_BEHAVIOURS = ("random-actions", "straight", "spin", "wall-follow")
BEHAVIOURS = AGENT_BEHAVIOURS + SCRIPTED_BEHAVIOURS
LABELS = {
    "frontier": "frontier",
    "cross-pass": "cross-pass",
    "greedy": "greedy",
    "random-actions": "random actions",
    "straight": "driving straight",
    "spin": "spinning in place",
    "wall-follow": "wall following",
}
#: The behaviours whose per-step rewards are kept (reward scale, horizon, VecNormalize).
TRACED = ("random-actions", "frontier")
#: Pairs (a, b) whose difference b − a the signal-to-noise table shows.
SNR_PAIRS = (
    ("random-actions", "straight"),
    ("random-actions", "wall-follow"),
    ("random-actions", "frontier"),
    ("straight", "frontier"),
    ("greedy", "frontier"),
)
GAMMAS = (0.98, 0.99, 0.995, 0.999)
BUMP_INDEX = -6  # obs["state"]: ..., bump, x, y, sin, cos, known fraction
#: Per behaviour, its episodes (None: it cannot act in the env).
Runs = dict[str, list[dict[str, Any]] | None]


# ------------------------------------------------------------------------------- behaviours
class Scripted:
    """A scripted behaviour on the env's raw actions (continuous or discrete).

    ``random-actions``: ``action_space.sample()`` seeded with the episode seed; ``straight``:
    full speed ahead; ``spin``: turning left in place; ``wall-follow``: ahead curving right, and at
    a bump (``obs["state"]``'s bump flag) two steps back and five turning left (discrete: no
    reverse, seven turning left; contact is ignored while turning and for two steps ahead after, as
    a disc touching a wall still touches it while it turns), so that it follows the wall on its
    right.
    """

    def __init__(self, kind: str, env: gym.Env, seed: int) -> None:
        if kind not in SCRIPTED_BEHAVIOURS:
            raise ConfigError(f"unknown scripted behaviour {kind!r}: {SCRIPTED_BEHAVIOURS}")
        self.kind, self.env = kind, env
        self.discrete = isinstance(env.action_space, gym.spaces.Discrete)
        env.action_space.seed(seed)
        self.back = self.turn = self.grace = self.t = 0

    def _a(self, linear: float, angular: float, discrete: int) -> Any:
        return discrete if self.discrete else np.array([linear, angular], np.float32)

    def act(self, obs: dict[str, np.ndarray]) -> Any:
        self.t += 1
        if self.kind == "random-actions":
            return self.env.action_space.sample()
        if self.kind == "straight":
            return self._a(1.0, 0.0, 0)
        if self.kind == "spin":
            return self._a(0.0, 1.0, 1)
        if obs["state"][BUMP_INDEX] > 0.5 and not (self.back or self.turn or self.grace):
            self.back, self.turn = (0, 7) if self.discrete else (2, 5)  # a new bump
        if self.back:
            self.back -= 1
            return self._a(-1.0, 0.0, 0)
        if self.turn:
            self.turn -= 1
            self.grace = 0 if self.turn else 2  # the first steps ahead may still touch
            return self._a(0.0, 1.0, 1)
        self.grace = max(self.grace - 1, 0)
        return self._a(1.0, -0.2, 2 if self.t % 6 == 0 else 0)  # ahead, curving right


def _actor(env: gym.Env, behaviour: str, seed: int) -> Callable[[Any], Any]:
    if behaviour in SCRIPTED_BEHAVIOURS:
        return Scripted(behaviour, env, seed).act
    from sfw_gym.agents import make_agent

    agent = make_agent(behaviour)
    agent.reset(env, seed=seed)  # a ConfigError where it cannot act in this env
    return agent.act


def run_episode(env: gym.Env, behaviour: str, seed: int, trace: bool = False) -> dict[str, Any]:
    """One episode of ``behaviour`` on ``env`` reset with ``seed``: the return under the env's
    reward, its two parts (``reward_scale`` × ``info["info_gain_bits"]`` summed, and
    ``collision_penalty`` × the steps whose ``info["collisions"]`` grew), the final coverage; with
    ``trace`` also the per-step ``rewards`` and ``bits`` (reward_scale × bits)."""
    obs, info = env.reset(seed=seed)
    paid = env.unwrapped.config.reward
    act = _actor(env, behaviour, seed)
    collisions = info["collisions"]
    rewards: list[float] = []
    bits: list[float] = []
    bumps = 0
    done = False
    while not done:
        obs, reward, terminated, truncated, info = env.step(act(obs))
        bumped = info["collisions"] > collisions
        collisions = info["collisions"]
        bumps += bumped
        rewards.append(float(reward))
        bits.append(paid.reward_scale * float(info["info_gain_bits"]))
        done = terminated or truncated
    ret = math.fsum(rewards)
    bits_part = math.fsum(bits)
    out: dict[str, Any] = {
        "seed": seed,
        "floorplan": info["floorplan"],
        "return": ret,
        "bits_part": bits_part,
        "fine_part": paid.collision_penalty * bumps,
        "bumps": bumps,
        "coverage": float(info["coverage"]),
        "steps": len(rewards),
    }
    if trace:
        out["rewards"] = np.asarray(rewards, np.float64)
        out["bits"] = np.asarray(bits, np.float64)
    return out


def ranking(
    env_id: str,
    behaviours: Sequence[str] = BEHAVIOURS,
    episodes: int = 5,
    seed0: int = SEED0,
    traced: Sequence[str] = TRACED,
) -> dict[str, list[dict[str, Any]] | None]:
    """Per behaviour, its episodes on seeds ``seed0 + i`` (the same plans for every behaviour);
    None where the behaviour cannot act in ``env_id``."""
    env = gym.make(env_id)
    out: dict[str, list[dict[str, Any]] | None] = {}
    for b in behaviours:
        try:
            out[b] = [run_episode(env, b, seed0 + i, trace=b in traced) for i in range(episodes)]
        except ConfigError as exc:
            print(f"  {env_id}: {b} n/a ({exc})")
            out[b] = None
    env.close()
    return out


def ranking_table(env_id: str, runs: dict[str, list[dict[str, Any]] | None]) -> str:
    """The markdown table: behaviour, mean return [95 % t-interval], coverage, bits part, fine
    part, rank (1 = the highest mean return) and coverage rank (1 = the highest coverage)."""
    means = {b: float(np.mean([e["return"] for e in r])) for b, r in runs.items() if r}
    order = sorted(means, key=means.get, reverse=True)
    cov = {b: float(np.mean([e["coverage"] for e in r])) for b, r in runs.items() if r}
    cov_order = sorted(cov, key=cov.get, reverse=True)
    n = max((len(r) for r in runs.values() if r), default=0)
    lines = [
        f"**{env_id}** ({n} paired episodes, seeds {SEED0:,}+i)",
        "",
        "| behaviour | return [95 % CI] | coverage | bits part | fine part | bumps | rank "
        "| coverage rank |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for b, r in runs.items():
        if not r:
            lines.append(f"| {LABELS.get(b, b)} | n/a | | | | | | |")
            continue

        def m(key: str, fmt: str, r: list[dict[str, Any]] = r) -> str:
            return fmt.format(np.mean([e[key] for e in r]))

        ret = [e["return"] for e in r]
        ret_text = mean_ci95_text(ret) if len(r) > 1 else f"{ret[0]:.2f}"
        lines.append(
            f"| {LABELS.get(b, b)} | {ret_text} | {m('coverage', '{:.3f}')} "
            f"| {m('bits_part', '{:.2f}')} | {m('fine_part', '{:.2f}')} | {m('bumps', '{:.0f}')} "
            f"| {order.index(b) + 1} | {cov_order.index(b) + 1} |"
        )
    return "\n".join(lines)


# --------------------------------------------------------------------------------- variance
def two_way_shares(y: np.ndarray) -> dict[str, float]:
    """Shares of the total sum of squares of ``y`` (rows: policies, columns: plans) between
    plans, between policies and residual (a two-way decomposition without interaction)."""
    y = np.asarray(y, np.float64)
    grand = y.mean()
    rows = y.mean(axis=1, keepdims=True)
    cols = y.mean(axis=0, keepdims=True)
    total = float(((y - grand) ** 2).sum())
    plans = float(y.shape[0] * ((cols - grand) ** 2).sum())
    policies = float(y.shape[1] * ((rows - grand) ** 2).sum())
    resid = float(((y - rows - cols + grand) ** 2).sum())
    if total == 0:
        return {"plans": math.nan, "policies": math.nan, "residual": math.nan}
    return {"plans": plans / total, "policies": policies / total, "residual": resid / total}


def signal_to_noise(a: Sequence[float], b: Sequence[float]) -> dict[str, float]:
    """The difference b − a paired by plan: its mean, the mean ÷ the return's spread across
    plans (pooled standard deviation of a and b: what an advantage without a plan-aware baseline
    sees), the mean ÷ the paired differences' standard deviation (a baseline that knew the plan),
    and the episodes per behaviour that make the difference two standard errors without a
    baseline, (2 / snr)²."""
    a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)
    d = b - a
    spread = math.sqrt((a.var(ddof=1) + b.var(ddof=1)) / 2) if len(a) > 1 else math.nan
    snr = d.mean() / spread if spread > 0 else math.nan
    paired = d.mean() / d.std(ddof=1) if len(d) > 1 and d.std(ddof=1) > 0 else math.nan
    return {
        "mean_difference": float(d.mean()),
        "plan_std": spread,
        "snr_unpaired": float(snr),
        "snr_paired": float(paired),
        "episodes_needed": float((2 / snr) ** 2) if snr and math.isfinite(snr) else math.nan,
    }


def variance_section(all_runs: dict[str, Runs]) -> tuple[str, dict]:
    lines = [
        "| id | behaviours × plans | between plans | between behaviours | residual |",
        "|---|---|---|---|---|",
    ]
    out: dict[str, Any] = {}
    for env_id, runs in all_runs.items():
        ok = {b: r for b, r in runs.items() if r}
        groups = {"all": list(ok)}
        close = [b for b in (*AGENT_BEHAVIOURS, "random-actions", "wall-follow") if b in ok]
        if 1 < len(close) < len(ok):
            groups["explorers (no straight, no spin)"] = close
        out[env_id] = {"shares": {}, "snr": {}}
        for name, members in groups.items():
            y = np.array([[e["return"] for e in ok[b]] for b in members])
            if y.shape[1] < 2 or y.shape[0] < 2:
                continue
            s = two_way_shares(y)
            out[env_id]["shares"][name] = {**s, "behaviours": members}
            lines.append(
                f"| {env_id} | {name}: {y.shape[0]} × {y.shape[1]} | {s['plans']:.2f} "
                f"| {s['policies']:.2f} | {s['residual']:.2f} |"
            )
    lines += [
        "",
        "| id | b − a | mean difference | return's std across plans | SNR (no baseline) "
        "| SNR (paired by plan) | episodes for 2 s.e. |",
        "|---|---|---|---|---|---|---|",
    ]
    for env_id, runs in all_runs.items():
        for a, b in SNR_PAIRS:
            if not (runs.get(a) and runs.get(b)) or len(runs[a]) < 2:
                continue
            s = signal_to_noise([e["return"] for e in runs[a]], [e["return"] for e in runs[b]])
            out[env_id]["snr"][f"{b} - {a}"] = s
            lines.append(
                f"| {env_id} | {LABELS[b]} − {LABELS[a]} | {s['mean_difference']:+.2f} "
                f"| {s['plan_std']:.2f} | {s['snr_unpaired']:+.2f} | {s['snr_paired']:+.2f} "
                f"| {_count(s['episodes_needed'])} |"
            )
    return "\n".join(lines), out


def _count(x: float) -> str:
    return "< 1" if x < 1 else f"{x:.0f}" if x >= 10 else f"{x:.1f}"


# ------------------------------------------------------------------------------ scale, horizon
def effective_horizon(gamma: float) -> float:
    """1 / (1 − γ) steps: the horizon over which a discounted return weighs rewards."""
    return 1.0 / (1.0 - gamma)


def returns_to_go(rewards: np.ndarray, gamma: float) -> np.ndarray:
    """G_t = r_t + γ G_{t+1} for every step t of one episode."""
    g = np.empty(len(rewards))
    acc = 0.0
    for t in range(len(rewards) - 1, -1, -1):
        acc = rewards[t] + gamma * acc
        g[t] = acc
    return g


def vecnormalize_scale(episodes: Sequence[np.ndarray], gamma: float = 0.99) -> float:
    """The standard deviation VecNormalize divides the reward by, once its running statistics
    have converged over ``episodes`` (run one after another in one env): SB3 keeps the discounted
    return R_t = γ R_{t−1} + r_t (0 at each episode's start) and divides by sqrt(var(R) + 1e-8)."""
    values = []
    for rewards in episodes:
        acc = 0.0
        for r in rewards:
            acc = gamma * acc + r
            values.append(acc)
    return float(math.sqrt(np.var(values) + 1e-8))


def scale_section(
    env_id: str, runs: Runs, step_m: float, max_steps: int, penalty: float
) -> tuple[str, dict]:
    traced = {b: runs[b] for b in TRACED if runs.get(b)}
    out: dict[str, Any] = {"env_id": env_id, "step_m": step_m, "per_step": {}, "horizon": []}
    lines = [
        f"Per-step reward on {env_id} (all steps of the ranking's episodes):",
        "",
        "| behaviour | mean | std | steps with a fine | 1st pct | 99th pct | max "
        "| return's std across plans |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for b, r in traced.items():
        rw = np.concatenate([e["rewards"] for e in r])
        fined = np.concatenate([e["rewards"] - e["bits"] for e in r]) < -0.5 * penalty
        s = {
            "mean": float(rw.mean()),
            "std": float(rw.std()),
            "fine_fraction": float(fined.mean()),
            "p01": float(np.percentile(rw, 1)),
            "p99": float(np.percentile(rw, 99)),
            "max": float(rw.max()),
            "return_std": float(np.std([e["return"] for e in r], ddof=1)) if len(r) > 1 else 0.0,
        }
        out["per_step"][b] = s
        lines.append(
            f"| {LABELS[b]} | {s['mean']:+.4f} | {s['std']:.4f} | {s['fine_fraction']:.3f} "
            f"| {s['p01']:+.3f} | {s['p99']:+.3f} | {s['max']:+.3f} | {s['return_std']:.2f} |"
        )
    front = traced.get("frontier")
    lines += [
        "",
        f"Effective horizon 1/(1−γ) ({step_m:.2f} m per step at full speed; episodes of "
        f"{max_steps:,} steps); frontier's bits earned after that step, as a share of its "
        "episode's bits:",
        "",
        "| γ | horizon [steps] | [m at full speed] | share of the episode "
        "| frontier's bits after it |",
        "|---|---|---|---|---|",
    ]
    for gamma in (*GAMMAS,):
        h = effective_horizon(gamma)
        shares = [e["bits"][round(h) :].sum() / max(e["bits"].sum(), 1e-12) for e in front or []]
        after = float(np.mean(shares)) if shares else math.nan
        out["horizon"].append({"gamma": gamma, "steps": h, "metres": h * step_m, "after": after})
        lines.append(
            f"| {gamma} | {h:.0f} | {h * step_m:.0f} | {h / max_steps:.3f} | {after:.2f} |"
        )
    lines += [
        "",
        "Discounted vs undiscounted return: G₀ with γ = 0.99 and 1, mean ± std across plans, and "
        "the correlation, over every step t of every episode, of the return-to-go G_t with "
        "γ = 0.99 (what the critic learns) with the undiscounted G_t (what the episode pays):",
        "",
        "| behaviour | G₀ (γ = 0.99) | G₀ (γ = 1) | corr(G_t^0.99, G_t^1) | corr over t ≥ 100 |",
        "|---|---|---|---|---|",
    ]
    out["discounted"] = {}
    for b, r in traced.items():
        g99 = [returns_to_go(e["rewards"], 0.99) for e in r]
        g1 = [returns_to_go(e["rewards"], 1.0) for e in r]
        c_all = float(np.corrcoef(np.concatenate(g99), np.concatenate(g1))[0, 1])
        late99 = np.concatenate([g[100:] for g in g99])
        late1 = np.concatenate([g[100:] for g in g1])
        c_late = float(np.corrcoef(late99, late1)[0, 1])
        d = {
            "g0_099": [float(g[0]) for g in g99],
            "g0_1": [float(g[0]) for g in g1],
            "corr": c_all,
            "corr_after_100": c_late,
        }
        out["discounted"][b] = d
        lines.append(
            f"| {LABELS[b]} | {np.mean(d['g0_099']):+.2f} ± {np.std(d['g0_099'], ddof=1):.2f} "
            f"| {np.mean(d['g0_1']):+.2f} ± {np.std(d['g0_1'], ddof=1):.2f} | {c_all:.2f} "
            f"| {c_late:.2f} |"
        )
    # VecNormalize
    lines += [
        "",
        "VecNormalize (γ = 0.99): the std of the discounted return it divides the reward by, and "
        "the per-step reward after the division:",
        "",
        "| behaviour | std of R_t | normalised reward: mean | std | fine | 99th pct |",
        "|---|---|---|---|---|---|",
    ]
    out["vecnormalize"] = {}
    for b, r in traced.items():
        scale = vecnormalize_scale([e["rewards"] for e in r], 0.99)
        rw = np.clip(np.concatenate([e["rewards"] for e in r]) / scale, -10, 10)
        v = {
            "scale": scale,
            "mean": float(rw.mean()),
            "std": float(rw.std()),
            "fine": penalty / scale,
            "p99": float(np.percentile(rw, 99)),
        }
        out["vecnormalize"][b] = v
        lines.append(
            f"| {LABELS[b]} | {scale:.3f} | {v['mean']:+.3f} | {v['std']:.3f} | −{v['fine']:.2f} "
            f"| {v['p99']:+.2f} |"
        )
    return "\n".join(lines), out


# ------------------------------------------------------------------------------ the waypoint policy
def monitor_returns(path: Path) -> np.ndarray:
    """The episode returns (column ``r``) of an SB3 monitor CSV."""
    import csv

    with path.open(encoding="utf-8") as f:
        next(f)  # the JSON header line
        return np.array([float(row["r"]) for row in csv.DictReader(f)])


def entropy_ratio(probs: np.ndarray) -> float:
    """The distribution's entropy ÷ the uniform's (log n): 1 = uniform."""
    p = np.asarray(probs, np.float64)
    p = p[p > 0]
    return float(-(p * np.log(p)).sum() / math.log(len(probs)))


def waypoint_episode(env: gym.Env, model: Any, seed: int, mode: str) -> dict[str, Any]:
    """One episode of the waypoint wrapper with waypoints from the policy's ``mode``
    (``sampled``, ``deterministic``) or uniformly ``random``; per decision the reward, the block
    and the policy's entropy ratio at that state."""
    import torch

    rng = np.random.default_rng(seed)
    obs, _ = env.reset(seed=seed)
    keys = model.observation_space.spaces
    rewards, blocks, ratios, top = [], [], [], []
    done = False
    while not done:
        with torch.no_grad():
            tensor, _ = model.policy.obs_to_tensor({k: v for k, v in obs.items() if k in keys})
            p = model.policy.get_distribution(tensor).distribution.probs[0].numpy()
        p = p.astype(np.float64)
        p /= p.sum()
        ratios.append(entropy_ratio(p))
        top.append(float(p.max()))
        if mode == "deterministic":
            a = int(np.argmax(p))
        elif mode == "sampled":
            a = int(rng.choice(len(p), p=p))
        else:
            a = int(rng.integers(len(p)))
        obs, reward, terminated, truncated, info = env.step(a)
        rewards.append(float(reward))
        blocks.append(a)
        done = terminated or truncated
    counts = np.bincount(blocks, minlength=len(p))
    return {
        "seed": seed,
        "mode": mode,
        "return": float(np.sum(rewards)),
        "coverage": float(info["coverage"]),
        "decisions": len(rewards),
        "rewards": rewards,
        "distinct_blocks": int((counts > 0).sum()),
        "top_block_share": float(counts.max() / len(blocks)),
        "entropy_ratio": ratios,
        "max_prob": top,
    }


def waypoint_section(model_dir: Path, episodes: int) -> tuple[str, dict]:
    import torch
    import yaml
    from stable_baselines3 import PPO

    from sfw_gym.envs.waypoint import WaypointWrapper
    from sfw_gym.rl.runs import find_model
    from sfw_gym.rl.waypoint_agent import waypoint_settings

    out: dict[str, Any] = {"model": str(model_dir)}
    r = monitor_returns(model_dir / "train_0.monitor.csv")
    first, last = r[:300], r[-300:]
    out["monitor"] = {
        "episodes": len(r),
        "first_300": mean_ci95(first),
        "last_300": mean_ci95(last),
        "episode_std": float(r.std(ddof=1)),
    }
    lines = [
        f"Its monitor log ({len(r):,} training episodes, sampled waypoints): return "
        f"{mean_ci95_text(first)} over the first 300 episodes, {mean_ci95_text(last)} over the "
        f"last 300; one episode's return has std {r.std(ddof=1):.1f} across episodes.",
    ]
    evals = np.load(model_dir / "eval" / "evaluations.npz")
    out["evaluations"] = {
        "timesteps": evals["timesteps"].tolist(),
        "mean_return": evals["results"].mean(axis=1).tolist(),
        "mean_length": evals["ep_lengths"].mean(axis=1).tolist(),
    }
    lines.append(
        "Its held-out evaluations (deterministic, 5 episodes each, every 10,000 waypoints): mean "
        "return "
        + ", ".join(f"{x:.0f}" for x in out["evaluations"]["mean_return"])
        + "; waypoints per episode "
        + ", ".join(f"{x:.0f}" for x in out["evaluations"]["mean_length"])
        + "."
    )
    if episodes <= 0:
        return "\n".join(lines), out
    torch.set_num_threads(1)
    config = yaml.safe_load((model_dir / "config.yml").read_text(encoding="utf-8"))
    model = PPO.load(find_model(model_dir), device="cpu")
    env = WaypointWrapper(gym.make(config["env_id"]), **(waypoint_settings(config) or {}))
    runs = {
        mode: [waypoint_episode(env, model, SEED0 + i, mode) for i in range(episodes)]
        for mode in ("sampled", "deterministic", "random")
    }
    out["rollouts"] = {
        m: [{k: v for k, v in e.items() if k not in ("rewards", "entropy_ratio", "max_prob")}
            for e in eps]
        for m, eps in runs.items()
    }  # fmt: skip
    lines += [
        "",
        f"Rollouts through `WaypointWrapper` on {episodes} validation plans (seeds {SEED0:,}+i), "
        "paired:",
        "",
        "| waypoints | return | coverage | decisions | reward per decision: mean | std within "
        "episodes | std of its plan means | distinct blocks | most frequent block's share "
        "| policy entropy ÷ uniform | policy's top probability |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for mode, eps in runs.items():
        per_dec = [np.mean(e["rewards"]) for e in eps]
        within = np.mean([np.std(e["rewards"]) for e in eps])
        ratios = np.concatenate([e["entropy_ratio"] for e in eps])
        tops = np.concatenate([e["max_prob"] for e in eps])
        row = {
            "return": float(np.mean([e["return"] for e in eps])),
            "coverage": float(np.mean([e["coverage"] for e in eps])),
            "decisions": float(np.mean([e["decisions"] for e in eps])),
            "reward_per_decision": float(np.mean(per_dec)),
            "within_std": float(within),
            "between_plan_std": float(np.std(per_dec, ddof=1)) if len(eps) > 1 else math.nan,
            "distinct_blocks": float(np.mean([e["distinct_blocks"] for e in eps])),
            "top_block_share": float(np.mean([e["top_block_share"] for e in eps])),
            "entropy_ratio": {"mean": float(ratios.mean()), "min": float(ratios.min()),
                              "max": float(ratios.max())},
            "max_prob": {"mean": float(tops.mean()), "max": float(tops.max())},
        }  # fmt: skip
        out.setdefault("summary", {})[mode] = row
        e = row["entropy_ratio"]
        lines.append(
            f"| {'policy, ' + mode if mode != 'random' else 'uniformly random'} "
            f"| {row['return']:.1f} | {row['coverage']:.3f} | {row['decisions']:.0f} "
            f"| {row['reward_per_decision']:+.3f} | {row['within_std']:.3f} "
            f"| {row['between_plan_std']:.3f} | {row['distinct_blocks']:.0f} "
            f"| {row['top_block_share']:.2f} | {e['mean']:.3f} (min {e['min']:.3f}) "
            f"| {row['max_prob']['mean']:.3f} (max {row['max_prob']['max']:.3f}) |"
        )
    pol = [e["return"] for e in runs["sampled"]]
    rnd = [e["return"] for e in runs["random"]]
    if episodes > 1:
        s = signal_to_noise(rnd, pol)
        dec = [np.mean(a["rewards"]) - np.mean(b["rewards"])
               for a, b in zip(runs["sampled"], runs["random"], strict=True)]  # fmt: skip
        within = out["summary"]["sampled"]["within_std"]
        out["snr_sampled_vs_random"] = {**s, "per_decision_difference": float(np.mean(dec))}
        lines += [
            "",
            f"Sampled policy − random waypoints, paired: return {s['mean_difference']:+.2f} "
            f"against a std of {s['plan_std']:.2f} across plans (SNR {s['snr_unpaired']:+.2f}, "
            f"{_count(s['episodes_needed'])} episodes per policy for 2 standard errors); per "
            "decision "
            f"{np.mean(dec):+.4f} against a within-episode std of {within:.3f} and a std of "
            f"{out['summary']['sampled']['between_plan_std']:.3f} between plans' means "
            f"(per-decision SNR {np.mean(dec) / within:+.3f}: about "
            f"{(2 * within / np.mean(dec)) ** 2:,.0f} decisions for 2 standard errors, if they "
            "were independent).",
        ]
    env.close()
    return "\n".join(lines), out


def wall_thickness_cells(truth_u8: np.ndarray) -> int:
    """The commonest length of a run of wall cells (0) along the grid's rows: a wall's thickness
    in cells (the walls across the rows)."""
    runs = []
    for row in truth_u8 == 0:
        d = np.diff(np.r_[0, row.astype(np.int8), 0])
        runs.extend((np.flatnonzero(d == -1) - np.flatnonzero(d == 1)).tolist())
    return int(np.argmax(np.bincount(runs))) if runs else 0


def cnn_section(episodes: int = 10) -> tuple[str, dict]:
    """The first attempt's architecture: SB3's MultiInputPolicy (NatureCNN per image) on the
    waypoint wrapper's observation, and the map image's metres per pixel on validation plans."""
    import torch
    from stable_baselines3.common.policies import MultiInputActorCriticPolicy

    from sfw_gym.envs.waypoint import WaypointWrapper

    env = WaypointWrapper(gym.make("SfW-Explore-v0"))
    sizes = []
    for i in range(episodes):
        env.reset(seed=SEED0 + i)
        sfw = env.unwrapped
        rows, cols = sfw.grid.shape
        res = sfw.grid.resolution_m
        m_per_px = sfw.obs_builder.cells_per_px * res
        sizes.append(
            {"plan_m": [cols * res, rows * res], "m_per_px": m_per_px, "px_per_m": 1 / m_per_px,
             "cells_per_px": sfw.obs_builder.cells_per_px,
             "wall_m": wall_thickness_cells(sfw.scene.truth_u8) * res}
        )  # fmt: skip
    m = np.array([s["m_per_px"] for s in sizes])
    policy = MultiInputActorCriticPolicy(
        env.observation_space, env.action_space, lr_schedule=lambda _: 3e-4
    )
    parts = {
        name: sum(p.numel() for p in module.parameters())
        for name, module in policy.features_extractor.extractors.items()
    }
    total = sum(p.numel() for p in policy.parameters())
    from sfw_gym.rl.policy import WaypointPolicy

    pointer = sum(
        p.numel()
        for p in WaypointPolicy(
            env.observation_space, env.action_space, lr_schedule=lambda _: 3e-4
        ).parameters()
    )
    cnn = policy.features_extractor.extractors["map"]
    shapes = []
    x = torch.zeros((1, *env.observation_space["map"].shape))
    for layer in cnn.cnn:
        x = layer(x)
        if isinstance(layer, torch.nn.Conv2d):
            shapes.append(tuple(x.shape[1:]))
    first = cnn.cnn[0]
    k, s = first.kernel_size[0], first.stride[0]
    out = {
        "plans": sizes,
        "m_per_px": {"min": float(m.min()), "median": float(np.median(m)), "max": float(m.max())},
        "first_layer": {"kernel_px": k, "stride_px": s, "kernel_m": [k * m.min(), k * m.max()],
                        "stride_m": [s * m.min(), s * m.max()]},
        "cells_sampled": [float(1 / max(x["cells_per_px"], 1) ** 2) for x in sizes],
        "parameters": {"total": total, "extractors": parts, "waypoint_policy": pointer},
        "map_conv_shapes": shapes,
        "features_dim": policy.features_extractor.features_dim,
    }  # fmt: skip
    env.close()
    wall_px = [x["wall_m"] / x["m_per_px"] for x in sizes]
    walls = [x["wall_m"] for x in sizes]
    out["wall_px"] = wall_px
    blocks = env.observation_space["map"].shape[-1] / 8  # px per waypoint block (8 × 8)
    text = (
        f"The first attempt's network (SB3 `MultiInputPolicy` on the waypoint observation): "
        f"{total:,} parameters (the shipped `WaypointPolicy`: {pointer:,}), of which the map "
        f"image's NatureCNN {parts['map']:,} and the local crop's {parts['local']:,}. On "
        f"{episodes} "
        f"validation plans ({min(x['plan_m'][0] for x in sizes):.0f}–"
        f"{max(x['plan_m'][0] for x in sizes):.0f} m wide) one map pixel is "
        f"{m.min():.2f}–{m.max():.2f} m (median {np.median(m):.2f}; "
        f"{1 / m.max():.1f}–{1 / m.min():.1f} px per m); a wall ({min(walls):.1f}–"
        f"{max(walls):.1f} m thick) is {min(wall_px):.1f}–{max(wall_px):.1f} px wide and the robot "
        f"a 3×3 px square. NatureCNN's first layer ({k}×{k} px, stride {s}) spans "
        f"{k * m.min():.1f}–{k * m.max():.1f} m and steps {s * m.min():.1f}–{s * m.max():.1f} m; "
        "the map image's conv stack gives "
        + " → ".join("×".join(map(str, sh)) for sh in shapes)
        + f": a {shapes[-1][-1]}×{shapes[-1][-1]} grid, coarser than the 8×8 waypoint blocks "
        f"it must choose among ({blocks:.0f} px each), flattened into dense layers that must learn "
        f"which block is which ({policy.features_extractor.features_dim} features in all). The "
        "images are north-up: the same corridor ahead of the robot is a different image for every "
        "heading, and nothing in NatureCNN is rotation-equivariant."
    )
    return text, out


# ------------------------------------------------------------------------------------ main
def _untraced(episode: dict[str, Any]) -> dict[str, Any]:
    return {k: v for k, v in episode.items() if k not in ("rewards", "bits")}


def _jsonable(x: Any) -> Any:
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, (np.floating, np.integer)):
        return x.item()
    if isinstance(x, float) and not math.isfinite(x):
        return None
    return x


def main(argv: Sequence[str] | None = None) -> None:
    p = argparse.ArgumentParser(
        description=__doc__.splitlines()[0], formatter_class=argparse.RawDescriptionHelpFormatter
    )
    p.add_argument("--ids", default=",".join(DEFAULT_IDS), help="explore ids, comma-separated")
    p.add_argument("--episodes", type=int, default=5, help="paired episodes per behaviour and id")
    p.add_argument("--behaviours", default=",".join(BEHAVIOURS), help="comma-separated")
    p.add_argument("--waypoint-episodes", type=int, default=3,
                   help="waypoint-policy rollouts per mode (0: its logs only)")  # fmt: skip
    p.add_argument(
        "--waypoint-model", default=None, help="the waypoint run's folder (default: the shipped)"
    )
    p.add_argument("--out", default="runs/diagnosis")
    args = p.parse_args(argv)
    ids = [s for s in args.ids.split(",") if s]
    behaviours = [s for s in args.behaviours.split(",") if s]
    unknown = [b for b in behaviours if b not in BEHAVIOURS]
    if unknown:
        p.error(f"unknown behaviours {unknown}; known: {', '.join(BEHAVIOURS)}")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    start_cpu, start = time.process_time(), time.perf_counter()
    command = "python scripts/studies/ppo_diagnosis.py " + " ".join(
        argv if argv is not None else __import__("sys").argv[1:]
    )
    md = [f"`{command.strip()}` ({time.strftime('%Y-%m-%d')})", ""]
    result: dict[str, Any] = {"command": command.strip(), "ids": ids, "episodes": args.episodes}

    def emit(text: str) -> None:
        print(text + "\n", flush=True)
        md.append(text + "\n")

    emit("## 1. The reward's ranking of known behaviours")
    all_runs: dict[str, Runs] = {}
    for env_id in ids:
        all_runs[env_id] = ranking(env_id, behaviours, args.episodes)
        emit(ranking_table(env_id, all_runs[env_id]))
    result["ranking"] = {
        env_id: {b: None if r is None else [_untraced(e) for e in r] for b, r in runs.items()}
        for env_id, runs in all_runs.items()
    }

    emit("## 2. Between plans or between policies")
    text, result["variance"] = variance_section(all_runs)
    emit(text)

    scale_id = next(
        (i for i in ("SfW-Explore-v0", *ids) if i in all_runs and all_runs[i].get("frontier")), None
    )
    if scale_id is not None:
        emit("## 3–4. Reward scale, horizon, VecNormalize")
        env = gym.make(scale_id)
        cfg = env.unwrapped.config
        step_m = cfg.robot.max_linear_speed_m_s * cfg.robot.control_period_s
        text, result["scale"] = scale_section(
            scale_id,
            all_runs[scale_id],
            step_m,
            cfg.explore.max_steps,
            cfg.reward.collision_penalty,
        )
        env.close()
        emit(text)

    emit("## 5. The waypoint policy and the first attempt's CNN")
    from sfw_gym.core.data import DEFAULT_WAYPOINT_MODEL_DIR

    model_dir = Path(args.waypoint_model or DEFAULT_WAYPOINT_MODEL_DIR)
    text, result["waypoint"] = waypoint_section(model_dir, args.waypoint_episodes)
    emit(text)
    text, result["cnn"] = cnn_section()
    emit(text)

    cpu, wall = time.process_time() - start_cpu, time.perf_counter() - start
    result["cpu_s"], result["wall_s"] = cpu, wall
    emit(f"CPU {cpu:.0f} s, wall {wall:.0f} s.")
    (out / "diagnosis.md").write_text("\n".join(md), encoding="utf-8")
    (out / "diagnosis.json").write_text(json.dumps(_jsonable(result), indent=1), encoding="utf-8")
    print(f"wrote {out / 'diagnosis.md'} and {out / 'diagnosis.json'}")


if __name__ == "__main__":
    main()
