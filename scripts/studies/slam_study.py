"""Radio SLAM study (issue 15): drift × pose source, AP density, router-position error, false
closures, speed. Frontier agent, held-out generated plans (seeds 2,000,000+), mean [95 % CI].

    python scripts/studies/slam_study.py [--plans 20] [--workers 2] [--out runs/slam_study]
    python scripts/studies/slam_study.py --speed 3      # env ms/step by pose source, one process

Writes ``OUT/tables.md`` (the tables for docs/results/slam.md) and ``OUT/records.json``. Every table
pairs its rows on the same plans and start poses (the pose source changes where the robot maps,
never where it drives: the same actions give the same true path only under the same agent, so
each pose source runs its own frontier episode on the same plan and seed).

- Drift: odometry noise none / low / mid / high (translation std as a fraction of each step's
  travel, heading std per step) × pose source odometry / radio_slam / true, 16 background APs:
  final ATE (unaligned: the estimate starts at the true pose), coverage, free-IoU, wall
  precision, env and agent milliseconds per step.
- AP density: mid drift, odometry runs with 2 … 32 background APs, Radio SLAM offline → ATE.
- Router-position error: the true-pose runs without drift mapped again with the routers'
  assumed positions moved 0 / 0.5 / 1 / 2 m in a random direction → free-IoU, wall precision.
- False closures: mid drift, 10 % more closures between random keyframes far apart, claiming
  they lie 0–2 m apart → ATE against the run without them.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing as mp
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np

from sfw_gym.evaluation.stats import compare_paired
from sfw_gym.evaluation.stats import mean_ci95_text as ci

DRIFT = {  # translation std (fraction of a step's travel), heading std per step (rad)
    "none": (0.0, 0.0),
    "low": (0.02, 0.01),
    "mid": (0.05, 0.02),  # SfW-ExploreDrift-v0 / SfW-ExploreRadioSLAM-v0
    "high": (0.10, 0.04),
}
SOURCES = ("odometry", "radio_slam", "true")
AP_COUNTS = (2, 4, 8, 16, 32)
ROUTER_ERRORS_M = (0.0, 0.5, 1.0, 2.0)
FIRST_SEED = 2_000_000


def episode(job: dict[str, Any]) -> dict[str, Any]:
    """One frontier episode; the record and, when asked, the run's log."""
    import gymnasium as gym

    import sfw_gym  # noqa: F401  (registration)
    from sfw_gym.agents import FrontierAgent

    trans, heading = DRIFT[job["drift"]]
    robot = {"odometry_translation_std": trans, "odometry_heading_std_rad": heading}
    env = gym.make(
        "SfW-Explore-v0",
        robot=robot,
        n_background_aps=job["aps"],
        pose_source=job["source"],
    )
    obs, info = env.reset(seed=job["seed"])
    agent = FrontierAgent()
    agent.reset(env, seed=job["seed"])
    u = env.unwrapped
    log: dict[str, list] = {"odometry": [], "truth": [], "fingerprint": [], "bump": []}

    def keep(info: dict[str, Any]) -> None:
        log["odometry"].append(info["odometry_pose"].tolist())
        log["truth"].append(info["true_pose"].tolist())
        log["fingerprint"].append(np.nan_to_num(info["fingerprint"], nan=-100.0).tolist())
        log["bump"].append(bool(u.scene.robot.bumped))

    keep(info)
    env_s = agent_s = 0.0
    steps, done = 0, False
    while not done:
        t0 = time.perf_counter()
        action = agent.act(obs)
        t1 = time.perf_counter()
        obs, _, terminated, truncated, info = env.step(action)
        env_s += time.perf_counter() - t1
        agent_s += t1 - t0
        steps += 1
        keep(info)
        done = terminated or truncated
    record = {
        **{k: job[k] for k in ("drift", "source", "aps", "seed")},
        "steps": steps,
        "ate_m": info["ate_m"],
        "coverage": info["coverage"],
        "free_iou": info["free_iou"],
        "wall_precision": info["wall_precision"],
        "env_ms": 1e3 * env_s / steps,
        "agent_ms": 1e3 * agent_s / steps,
    }
    if job.get("log"):
        record["log"] = log
        record["rssi"] = u.rssi_history.view.tolist()
        record["routers"] = u.scene.radio.routers.tolist()
    return record


def remap_with_router_error(record: dict[str, Any], error_m: float, seed: int) -> dict[str, float]:
    """Map a logged run again along its true path with the routers assumed ``error_m`` off."""
    import gymnasium as gym

    from sfw_gym.mapping import SparseInverseKVisibility
    from sfw_gym.mapping import metrics as m

    env = gym.make("SfW-Explore-v0")
    env.reset(seed=record["seed"])  # the same plan: its grid, truth and mapper settings
    u = env.unwrapped
    rng = np.random.default_rng(seed)
    angle = rng.uniform(0, 2 * np.pi, len(record["routers"]))
    routers = np.array(record["routers"]) + error_m * np.column_stack(
        [np.cos(angle), np.sin(angle)]
    )
    mapper = SparseInverseKVisibility(u.grid, routers, u.config.mapper)
    for (x, y, theta), rssi, bump in zip(
        record["log"]["truth"], record["rssi"], record["log"]["bump"], strict=True
    ):
        mapper.update((x, y), np.asarray(rssi, np.float64), bump, theta)
    est, truth = mapper.occupancy_u8, u.scene.truth_u8
    return {"free_iou": m.free_iou(est, truth), "wall_precision": m.wall_precision(est, truth)}


def offline_slam(record: dict[str, Any], false_fraction: float = 0.0, seed: int = 0):
    """Radio SLAM on a logged run (odometry weighted by the run's noise): ATE, time."""
    from sfw_gym.slam import RadioSlamConfig, absolute_trajectory_error, radio_slam

    trans, heading = DRIFT[record["drift"]]
    cfg = RadioSlamConfig(
        odometry_sigma_m=max(trans * 0.1, 1e-3), odometry_sigma_rad=max(heading, 1e-3)
    )
    odometry = np.array(record["log"]["odometry"])
    prints = np.array(record["log"]["fingerprint"])
    prints[prints <= -100.0] = np.nan
    truth = np.array(record["log"]["truth"])
    extra = None
    if false_fraction:
        real = radio_slam(odometry, prints, cfg).closures
        rng = np.random.default_rng(seed)
        keys = np.arange(0, len(odometry), cfg.keyframe_every)
        n_false = max(1, round(false_fraction * len(real)))
        rows = []
        while len(rows) < n_false:
            i, j = np.sort(rng.choice(keys, 2, replace=False))
            if np.linalg.norm(truth[i, :2] - truth[j, :2]) > 5.0:  # truly far apart
                rows.append((i, j, rng.uniform(0.0, 2.0)))
        extra = np.array(rows)
    start = time.perf_counter()
    result = radio_slam(odometry, prints, cfg, extra_closures=extra)
    wall = time.perf_counter() - start
    return absolute_trajectory_error(result.poses, truth, align=False), wall, len(result.closures)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--plans", type=int, default=20)
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--out", default="runs/slam_study")
    p.add_argument("--speed", type=int, default=0, metavar="PLANS", help="only the speed table")
    args = p.parse_args()
    if args.speed:  # side by side in this process, mid drift
        print("| pose source | env ms/step | env steps/s | agent ms/step |\n|---|---:|---:|---:|")
        for source in SOURCES:
            rs = [
                episode({"drift": "mid", "source": source, "aps": 16, "seed": seed})
                for seed in range(FIRST_SEED, FIRST_SEED + args.speed)
            ]
            ms = float(np.mean([r["env_ms"] for r in rs]))
            agent = float(np.mean([r["agent_ms"] for r in rs]))
            print(f"| {source} | {ms:.3f} | {1e3 / ms:,.0f} | {agent:.3f} |")
        return
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    seeds = range(FIRST_SEED, FIRST_SEED + args.plans)
    jobs = [
        {"drift": d, "source": s, "aps": 16, "seed": seed, "log": (d, s) in LOGGED}
        for d in DRIFT
        for s in SOURCES
        for seed in seeds
    ]
    jobs += [
        {"drift": "mid", "source": "odometry", "aps": n, "seed": seed, "log": True}
        for n in AP_COUNTS
        if n != 16
        for seed in seeds
    ]
    start = time.perf_counter()
    with ProcessPoolExecutor(args.workers, mp_context=mp.get_context("spawn")) as pool:
        records = list(pool.map(episode, jobs))
    print(f"{len(records)} episodes in {time.perf_counter() - start:.0f} s")

    def rows(**match: Any) -> list[dict[str, Any]]:
        return [r for r in records if all(r[k] == v for k, v in match.items())]

    lines = [f"Frontier agent, {args.plans} held-out plans (seeds {FIRST_SEED:,}+), 3,000 steps."]
    lines.append("")
    lines += [
        "| drift (trans, heading) | pose source | ATE [m] | coverage | free-IoU | wall precision "
        "| env ms/step |",
        "|---|---|---:|---:|---:|---:|---:|",
    ]
    for d, (trans, heading) in DRIFT.items():
        for s in SOURCES:
            rs = rows(drift=d, source=s, aps=16)
            lines.append(
                f"| {d} ({trans}, {heading}) | {s} | {ci([r['ate_m'] for r in rs])} | "
                f"{ci([r['coverage'] for r in rs], '{:.3f}')} | "
                f"{ci([r['free_iou'] for r in rs], '{:.3f}')} | "
                f"{ci([r['wall_precision'] for r in rs], '{:.3f}')} | "
                f"{np.mean([r['env_ms'] for r in rs]):.2f} |"
            )
    lines += ["", "Paired radio_slam − true (mapping metrics), radio_slam − odometry (ATE); mean"]
    lines += ["[95 % seeded bootstrap interval] over seeds:", ""]
    lines += ["| drift | Δ ATE vs odometry [m] | Δ free-IoU vs true | Δ wall precision vs true |"]
    lines += ["|---|---:|---:|---:|"]
    for d in DRIFT:
        slam = {r["seed"]: r for r in rows(drift=d, source="radio_slam", aps=16)}
        odo = {r["seed"]: r for r in rows(drift=d, source="odometry", aps=16)}
        true = {r["seed"]: r for r in rows(drift=d, source="true", aps=16)}

        def diff(key: str, a: dict, b: dict, fmt: str) -> str:  # a − b, paired by seed
            return compare_paired([b[k][key] for k in seeds], [a[k][key] for k in seeds]).text(fmt)

        lines.append(
            f"| {d} | {diff('ate_m', slam, odo, '{:.2f}')} | "
            f"{diff('free_iou', slam, true, '{:+.3f}')} | "
            f"{diff('wall_precision', slam, true, '{:+.3f}')} |"
        )

    lines += ["", "AP density (mid drift; Radio SLAM offline on the odometry runs):", ""]
    lines += ["| background APs | ATE odometry [m] | ATE Radio SLAM [m] | closures |"]
    lines += ["|---:|---:|---:|---:|"]
    slam_times = []
    for n in AP_COUNTS:
        rs = rows(drift="mid", source="odometry", aps=n)
        results = [offline_slam(r) for r in rs]
        slam_times += [
            (len(r["log"]["odometry"]), w) for r, (_, w, _) in zip(rs, results, strict=True)
        ]
        lines.append(
            f"| {n} | {ci([r['ate_m'] for r in rs])} | {ci([a for a, _, _ in results])} | "
            f"{np.mean([c for _, _, c in results]):.0f} |"
        )

    lines += ["", "Router-position error (no drift, true pose; the routers assumed off):", ""]
    lines += ["| error [m] | free-IoU | wall precision |", "|---:|---:|---:|"]
    base = rows(drift="none", source="true", aps=16)
    for e in ROUTER_ERRORS_M:
        ms = [remap_with_router_error(r, e, r["seed"]) for r in base]
        lines.append(
            f"| {e} | {ci([m['free_iou'] for m in ms], '{:.3f}')} | "
            f"{ci([m['wall_precision'] for m in ms], '{:.3f}')} |"
        )

    lines += ["", "False closures (mid drift, 16 APs): 10 % more closures, each claiming two far "]
    lines += ["poses lie 0–2 m apart:", ""]
    rs = rows(drift="mid", source="odometry", aps=16)
    clean = [offline_slam(r)[0] for r in rs]
    dirty = [offline_slam(r, 0.10, r["seed"])[0] for r in rs]
    lines += [
        f"ATE without {ci(clean)} m, with {ci(dirty)} m; ratio (paired) "
        f"{ci([b / a for a, b in zip(clean, dirty, strict=True)], '{:.3f}')}.",
        "",
        f"Offline Radio SLAM time per run: {np.mean([w for _, w in slam_times]):.2f} s mean, "
        f"{max(w for _, w in slam_times):.2f} s max, at up to "
        f"{max(n for n, _ in slam_times):,} poses.",
    ]
    text = "\n".join(lines) + "\n"
    (out / "tables.md").write_text(text)
    slim = [{k: v for k, v in r.items() if k not in ("log", "rssi")} for r in records]
    (out / "records.json").write_text(json.dumps(slim, indent=1))
    print(text)


#: The runs whose logs the offline tables use.
LOGGED = {("none", "true"), ("mid", "odometry")}

if __name__ == "__main__":
    main()
