"""Radio+LiDAR SLAM study (issue 18): ATE of odometry, LiDAR-only, Radio SLAM and Radio+LiDAR
SLAM at two drift levels; LiDAR and WiFi-only map quality on the same runs; speed.

    python scripts/studies/lidar_study.py [--plans 20] [--workers 2] [--out runs/lidar_study]
    python scripts/studies/lidar_study.py --lidar '{"max_range_m": 4, "range_noise_std_m": 0.03}'
    ...

Each run: the frontier agent for 3,000 steps on a held-out generated plan (seeds 3,000,000+,
of 120–200 m², the generator's largest, so that its loops are long) with drifting odometry, 16
background APs and the simulated LiDAR (360 beams, 8 m, 1 cm noise); the four trajectories are
computed offline on
that one run (paired). Maps: a log-odds LiDAR map along each trajectory, and the WiFi-only
inverse k-visibility map along Radio SLAM's (what WiFi alone gets) and along the true path
(the WiFi mapper's best). Loop length of a run: the longest drive between two visits of the same
place (true poses ≤ 1 m apart); runs above the median are "long loops".

Writes ``OUT/tables.md`` and ``OUT/records.json``; mean [95 % CI] over runs.
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
from scipy.spatial import cKDTree

from sfw_gym.evaluation.stats import compare_paired
from sfw_gym.evaluation.stats import mean_ci95_text as ci
from sfw_gym.slam.radio_slam import travelled_m

DRIFT = {"mid": (0.05, 0.02), "high": (0.10, 0.04)}  # as scripts/studies/slam_study.py
METHODS = ("odometry", "lidar_only", "radio_slam", "radio_lidar")
FIRST_SEED = 3_000_000
STEPS = 3000


def loop_length_m(truth: np.ndarray, revisit_m: float = 1.0, min_gap: int = 50) -> float:
    """The longest drive between two poses within ``revisit_m`` of each other."""
    along = travelled_m(truth)
    pairs = cKDTree(truth[::5, :2]).query_pairs(revisit_m, output_type="ndarray") * 5
    pairs = pairs[pairs[:, 1] - pairs[:, 0] >= min_gap]
    return float(np.max(along[pairs[:, 1]] - along[pairs[:, 0]])) if len(pairs) else 0.0


def run(job: dict[str, Any]) -> dict[str, Any]:
    """One recorded run and every method on it."""
    from sfw_gym.evaluation.drives import record_frontier_drive
    from sfw_gym.mapping import SparseInverseKVisibility
    from sfw_gym.mapping import metrics as m
    from sfw_gym.mapping.lidar_map import LidarOccupancyMap
    from sfw_gym.slam import absolute_trajectory_error, lidar_slam, radio_slam

    trans, heading = DRIFT[job["drift"]]
    drive = record_frontier_drive(
        "SfW-Explore-v0",
        job["seed"],
        STEPS,
        robot={"odometry_translation_std": trans, "odometry_heading_std_rad": heading},
        generator={"area_m2": float(job["area_m2"])},
        n_background_aps=16,
        lidar=job["lidar"],
    )
    u = drive["env"]
    truth, odometry, prints = drive["truth"], drive["odometry"], drive["fingerprints"]
    ranges, scans, bumps = drive["lidar_ranges"], drive["keyframe_scans"], drive["bumps"]
    rssi, radio, lidar = u.rssi_history.view, drive["slam_config"], u.lidar

    timings: dict[str, float] = {}
    trajectories: dict[str, np.ndarray] = {"odometry": odometry}
    start = time.perf_counter()
    trajectories["radio_slam"] = radio_slam(odometry, prints, radio).poses
    timings["radio_slam_s"] = time.perf_counter() - start
    start = time.perf_counter()
    only = lidar_slam(odometry, scans, radio=radio)
    timings["lidar_only_s"] = time.perf_counter() - start
    trajectories["lidar_only"] = only.poses
    start = time.perf_counter()
    both = lidar_slam(odometry, scans, prints, radio=radio)
    timings["radio_lidar_s"] = time.perf_counter() - start
    trajectories["radio_lidar"] = both.poses
    timings["icp_calls"] = both.icp_calls + only.icp_calls

    truth_u8 = u.scene.truth_u8
    maps: dict[str, np.ndarray] = {}
    record: dict[str, Any] = {
        **{k: job[k] for k in ("drift", "seed")},
        "poses": len(odometry),
        "loop_m": loop_length_m(truth),
        "lidar_closures": len(both.lidar_closures),
        "lidar_only_closures": len(only.lidar_closures),
        "consecutive_registered": both.consecutive_registered,
        **timings,
    }
    for name, poses in trajectories.items():
        record[f"ate_{name}"] = absolute_trajectory_error(poses, truth, align=False)
        grid = LidarOccupancyMap(u.grid)
        for k in range(0, len(poses), 2):
            # a beam that returned nothing: free to the maximum range, unless it may have
            # dropped out (then it says nothing)
            keep = np.isfinite(ranges[k]) if lidar.config.dropout else slice(None)
            grid.integrate(poses[k], lidar.angles[keep], ranges[k][keep], lidar.config.max_range_m)
        est = grid.occupancy_u8()
        record[f"lidar_map_{name}"] = _scores(m, est, truth_u8)
        maps[f"LiDAR map, {name}"] = est
    for name, poses in (("radio_slam", trajectories["radio_slam"]), ("true", truth)):
        mapper = SparseInverseKVisibility(u.grid, u.scene.radio.routers, u.config.mapper)
        x0, y0, x1, y1 = u.grid.bounds
        for (x, y, theta), reading, bump in zip(poses, rssi, bumps, strict=True):
            if x0 <= x < x1 and y0 <= y < y1:  # as the env: nothing fused off the map
                mapper.update((x, y), np.asarray(reading, np.float64), bump, theta)
        record[f"wifi_map_{name}"] = _scores(m, mapper.occupancy_u8, truth_u8)
        maps[f"WiFi-only map, {name} pose"] = mapper.occupancy_u8.copy()
    if job.get("figure"):  # the maps of this run side by side, beside the truth
        record["maps"] = {"truth": truth_u8, **maps}
    return record


def _scores(m: Any, est: np.ndarray, truth: np.ndarray) -> dict[str, float]:
    return {
        "free_iou": m.free_iou(est, truth),
        "wall_precision": m.wall_precision(est, truth),
        "wall_recall": m.interior_wall_recall(est, truth),
    }


def tables(records: list[dict[str, Any]], plans: int) -> list[str]:
    lines = [
        f"Frontier agent, {plans} held-out generated plans (seeds {FIRST_SEED:,}+, 120–200 m²), "
        f"{STEPS:,} steps, 16 background APs, the LiDAR as OUT/tables.md's first line says "
        "(default 360 beams / 8 m / 1 cm); mean [95 % CI].",
        "",
        "| drift (trans, heading) | " + " | ".join(f"ATE {m} [m]" for m in METHODS) + " |",
        "|---|" + "---:|" * len(METHODS),
    ]
    for d, (trans, heading) in DRIFT.items():
        rs = [r for r in records if r["drift"] == d]
        lines.append(
            f"| {d} ({trans}, {heading}) | "
            + " | ".join(ci([r[f"ate_{m}"] for r in rs]) for m in METHODS)
            + " |"
        )
    lines += ["", "Paired differences, Radio+LiDAR − other [m] (negative: Radio+LiDAR better; mean"]
    lines += ["[95 % seeded bootstrap interval]):", ""]
    lines += [
        "| drift | runs | vs odometry | vs LiDAR-only | vs Radio SLAM |",
        "|---|---|---:|---:|---:|",
    ]
    for d in DRIFT:
        rs = [r for r in records if r["drift"] == d]
        median = float(np.median([r["loop_m"] for r in rs]))
        for label, sub in (
            ("all", rs),
            (f"long loops (> {median:.0f} m)", [r for r in rs if r["loop_m"] > median]),
            (f"short loops (≤ {median:.0f} m)", [r for r in rs if r["loop_m"] <= median]),
        ):
            lines.append(
                f"| {d} | {label}, {len(sub)} | "
                + " | ".join(
                    compare_paired(
                        [r[f"ate_{o}"] for r in sub], [r["ate_radio_lidar"] for r in sub]
                    ).text("{:.2f}")
                    for o in ("odometry", "lidar_only", "radio_slam")
                )
                + " |"
            )
    lines += ["", "Maps on the same runs (LiDAR map along each trajectory; WiFi-only map):", ""]
    lines += [
        "| drift | map | free-IoU | wall precision | interior wall recall |",
        "|---|---|---:|---:|---:|",
    ]
    for d in DRIFT:
        rs = [r for r in records if r["drift"] == d]
        for key, label in (
            *((f"lidar_map_{m}", f"LiDAR, {m}") for m in METHODS),
            ("wifi_map_radio_slam", "WiFi-only, Radio SLAM pose"),
            ("wifi_map_true", "WiFi-only, true pose"),
        ):
            lines.append(
                f"| {d} | {label} | "
                + " | ".join(
                    ci([r[key][s] for r in rs], "{:.3f}")
                    for s in ("free_iou", "wall_precision", "wall_recall")
                )
                + " |"
            )
    per_k = [1e3 * r["radio_lidar_s"] / r["poses"] for r in records]
    lines += [
        "",
        f"Speed: Radio+LiDAR SLAM {np.mean(per_k):.2f} s per 1,000 poses (incl. Radio SLAM and "
        f"{np.mean([r['icp_calls'] for r in records]) / 2:.0f} ICP calls per run), LiDAR-only "
        f"{np.mean([1e3 * r['lidar_only_s'] / r['poses'] for r in records]):.2f} s, Radio SLAM "
        f"{np.mean([1e3 * r['radio_slam_s'] / r['poses'] for r in records]):.2f} s; consecutive "
        f"keyframes registered {np.mean([r['consecutive_registered'] for r in records]):.1%}.",
    ]
    return lines


def save_figure(maps: dict[str, np.ndarray], path: Path, record: dict[str, Any]) -> None:
    """The run's maps in a row: the truth, the LiDAR map along each trajectory, WiFi-only."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(maps), figsize=(2.6 * len(maps), 3.2))
    for ax, (title, grid) in zip(axes, maps.items(), strict=True):
        ax.imshow(grid, cmap="gray", origin="lower", vmin=0, vmax=255)
        ax.set_title(title, fontsize=7)
        ax.axis("off")
    fig.suptitle(f"seed {record['seed']}, {record['drift']} drift (black wall, grey unknown)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--plans", type=int, default=20)
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--out", default="runs/lidar_study")
    p.add_argument(
        "--lidar", default="{}", help='LidarConfig overrides as JSON, e.g. {"max_range_m": 4}'
    )
    args = p.parse_args()
    lidar = json.loads(args.lidar)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(FIRST_SEED)
    areas = rng.uniform(120.0, 200.0, args.plans).round()
    jobs = [
        {
            "drift": d,
            "seed": FIRST_SEED + i,
            "area_m2": areas[i],
            "lidar": lidar,
            "figure": i == 0 and d == "mid",
        }
        for d in DRIFT
        for i in range(args.plans)
    ]
    start = time.perf_counter()
    with ProcessPoolExecutor(args.workers, mp_context=mp.get_context("spawn")) as pool:
        records = list(pool.map(run, jobs))
    print(f"{len(records)} runs in {time.perf_counter() - start:.0f} s")
    for record in records:
        if "maps" in record:
            save_figure(record.pop("maps"), out / "maps.png", record)
    (out / "records.json").write_text(json.dumps(records, indent=1))
    text = f"LiDAR overrides: {lidar or 'none'}\n\n" + "\n".join(tables(records, args.plans)) + "\n"
    (out / "tables.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
