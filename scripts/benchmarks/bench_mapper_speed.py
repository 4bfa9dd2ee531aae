"""Speed (and a quality sanity check) of SparseInverseKVisibility.update() on a synthetic world.

The world is built here from plain numpy, independent of ``sfw_gym.world``: a 15 x 15 m square
room split by one interior wall at x = 7.5 m with a 1 m door (y in [10, 11]); two routers; k by
segment crossing; RSSI from the log-distance model (20 dBm, PL(1 m) = 40.2 dB, n = 2) with
10 dB per wall and N(0, 2) dB noise, rounded to integers. The robot (radius 0.17 m) surveys the
left room with a lawnmower (0.3 m pass spacing, 0.05 m steps, 0.1 m from the walls), crosses the
door, then surveys the right room.

Prints median / mean / p95 microseconds per ``update()`` (k-means refits included) for a 0.05 m
grid and 2 routers, for ``router_policy="strongest"`` and ``"all"``, and the map metrics.

Rows "+k0" give the distance-aware estimator its calibration (``k0_level_dbm = P_tx - PL(1 m)``).

Usage: python scripts/benchmarks/bench_mapper_speed.py [--seed 0] [--repeats 3] [--noise-db 2]
                                            [--clearance 0.1] [--spacing 0.3]

Results: docs/results/mapping.md#what-mapping-costs.
"""

from __future__ import annotations

import argparse
import itertools
import time
from dataclasses import replace

import numpy as np

from sfw_gym.mapping import GridSpec, MapperConfig, SparseInverseKVisibility
from sfw_gym.mapping.metrics import evaluate_map, k_value_accuracy

SIDE_M = 15.0
WALL_X = 7.5
DOOR = (10.0, 11.0)
WALL_THICK_M = 0.1
ROBOT_R = 0.17
ROUTERS = np.array([[3.0, 4.0], [11.5, 11.0]])
# Interior wall as segments (the door is a gap); outer walls are never crossed from inside.
WALLS = np.array([[WALL_X, 0.0, WALL_X, DOOR[0]], [WALL_X, DOOR[1], WALL_X, SIDE_M]])


def count_walls(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """k per sample: number of wall segments properly crossed by segment a[i] -> b (vectorised)."""

    def cross(o, p, q):
        return (p[..., 0] - o[..., 0]) * (q[..., 1] - o[..., 1]) - (p[..., 1] - o[..., 1]) * (
            q[..., 0] - o[..., 0]
        )

    k = np.zeros(a.shape[0], np.int64)
    for w in WALLS:
        p, q = w[:2], w[2:]
        d1 = cross(p, q, a)
        d2 = cross(p, q, np.broadcast_to(b, a.shape))
        d3 = cross(a, np.broadcast_to(b, a.shape), np.broadcast_to(p, a.shape))
        d4 = cross(a, np.broadcast_to(b, a.shape), np.broadcast_to(q, a.shape))
        k += ((d1 * d2 < 0) & (d3 * d4 < 0)).astype(np.int64)
    return k


def polyline(points: list[tuple[float, float]], step: float) -> np.ndarray:
    """Points every ``step`` metres along a polyline."""
    out = []
    for (x0, y0), (x1, y1) in itertools.pairwise(points):
        n = max(1, int(np.ceil(np.hypot(x1 - x0, y1 - y0) / step)))
        t = np.arange(n) / n
        out.append(np.stack([x0 + t * (x1 - x0), y0 + t * (y1 - y0)], axis=1))
    out.append(np.array([points[-1]]))
    return np.concatenate(out)


def lawnmower(x0: float, x1: float, y0: float, y1: float, spacing: float, down: bool) -> list:
    """Waypoints of a boustrophedon survey of a rectangle (passes along x, first at x0)."""
    ys = np.arange(y0, y1 + 1e-9, spacing)
    pts = []
    for i, y in enumerate(ys[::-1] if down else ys):
        pts += [(x0, y), (x1, y)] if i % 2 == 0 else [(x1, y), (x0, y)]
    return pts


def trajectory(step: float = 0.05, clearance_m: float = 0.1, spacing_m: float = 0.3) -> np.ndarray:
    """Left-room survey, door crossing, right-room survey, ``clearance_m`` from the walls."""
    m = ROBOT_R + clearance_m
    half = WALL_THICK_M / 2
    left = lawnmower(m, WALL_X - half - m, m, SIDE_M - m, spacing_m, down=False)
    door_y = sum(DOOR) / 2
    transit = [(WALL_X - half - m, door_y), (WALL_X + half + m, door_y)]
    right = lawnmower(WALL_X + half + m, SIDE_M - m, m, SIDE_M - m, spacing_m, down=True)
    return polyline(left + transit + right, step)


def rssi_for(traj: np.ndarray, rng: np.random.Generator, noise_db: float):
    """RSSI (R columns, integer dBm) and true k at every trajectory point."""
    rssi = np.empty((traj.shape[0], len(ROUTERS)))
    k_true = np.empty((traj.shape[0], len(ROUTERS)), np.int64)
    for r, router in enumerate(ROUTERS):
        d = np.maximum(np.hypot(*(traj - router).T), 0.1)
        k = count_walls(traj, router)
        level = 20.0 - 40.2 - 20.0 * np.log10(d) - 10.0 * k
        rssi[:, r] = np.round(level + rng.normal(0.0, noise_db, d.shape))
        k_true[:, r] = k
    return np.maximum(rssi, -100.0), k_true


def truth_map(grid: GridSpec) -> np.ndarray:
    """Ground truth: 0 wall, 255 free, 127 outside."""
    xs, ys = grid.cell_centres()
    half = WALL_THICK_M / 2
    inside = (xs > -half) & (xs < SIDE_M + half) & (ys > -half) & (ys < SIDE_M + half)
    outer = inside & ((xs < half) | (xs > SIDE_M - half) | (ys < half) | (ys > SIDE_M - half))
    door = (ys > DOOR[0]) & (ys < DOOR[1])
    inner = (np.abs(xs - WALL_X) < half) & ~door
    out = np.full(grid.shape, 127, np.uint8)
    out[inside] = 255
    out[outer | inner] = 0
    return out


def run(config: MapperConfig, traj, rssi, k_true, grid, truth):
    """Time every update of one survey; return (µs per update array, metrics dict)."""
    mapper = SparseInverseKVisibility(grid, ROUTERS, config)
    times = np.empty(traj.shape[0])
    k_est = np.empty_like(k_true)
    clock = time.perf_counter_ns
    for i in range(traj.shape[0]):
        p = traj[i]
        r = rssi[i]
        t0 = clock()
        mapper.update(p, r)
        times[i] = (clock() - t0) / 1000.0
        k_est[i] = mapper.last_k
    metrics = evaluate_map(mapper.occupancy_u8, truth)
    metrics["k_accuracy"] = k_value_accuracy(k_est, k_true)
    metrics["refits"] = mapper.k_estimator.n_refits
    return times, metrics


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--repeats", type=int, default=3, help="timed runs per configuration")
    ap.add_argument("--noise-db", type=float, default=2.0)
    ap.add_argument("--resolution", type=float, default=0.05)
    ap.add_argument("--clearance", type=float, default=0.1, help="robot-wall gap of the survey, m")
    ap.add_argument("--spacing", type=float, default=0.3, help="lawnmower pass spacing, m")
    args = ap.parse_args()

    grid = GridSpec.covering((0.0, 0.0, SIDE_M, SIDE_M), args.resolution, margin_m=0.2)
    truth = truth_map(grid)
    traj = trajectory(clearance_m=args.clearance, spacing_m=args.spacing)
    rng = np.random.default_rng(args.seed)
    rssi, k_true = rssi_for(traj, rng, args.noise_db)
    print(
        f"grid {grid.shape[0]}x{grid.shape[1]} @ {grid.resolution_m} m, {len(ROUTERS)} routers, "
        f"{traj.shape[0]} samples, noise {args.noise_db} dB"
    )
    base = MapperConfig()
    run(base, traj[:300], rssi[:300], k_true[:300], grid, truth)  # compile / warm caches
    k0 = 20.0 - 40.2  # P_tx - PL(1 m): the calibration of the "+k0" rows
    configs = [
        ("strongest / distance_aware", base),
        ("all / distance_aware", replace(base, router_policy="all")),
        ("strongest / distance_aware+k0", replace(base, k0_level_dbm=k0)),
        ("all / distance_aware+k0", replace(base, k0_level_dbm=k0, router_policy="all")),
        ("strongest / kmeans", replace(base, k_estimator="kmeans")),
        ("all / kmeans", replace(base, k_estimator="kmeans", router_policy="all")),
    ]
    header = (
        f"{'policy / estimator':31s} {'median':>7s} {'mean':>7s} {'p95':>7s}  {'k-acc':>6s} "
        f"{'IoU':>6s} {'freeIoU':>7s} {'wallP':>6s} {'wallR':>6s} {'cover':>6s}"
    )
    print(header + "   (µs per update)")
    for name, cfg in configs:
        all_times = []
        for _ in range(args.repeats):
            times, m = run(cfg, traj, rssi, k_true, grid, truth)
            all_times.append(times)
        t = np.concatenate(all_times)
        print(
            f"{name:31s} {np.median(t):7.2f} {t.mean():7.2f} {np.percentile(t, 95):7.2f}  "
            f"{m['k_accuracy']:6.3f} {m['paper_iou']:6.3f} {m['free_iou']:7.3f} "
            f"{m['wall_precision']:6.3f} {m['interior_wall_recall']:6.3f} {m['coverage']:6.3f}"
        )


if __name__ == "__main__":
    main()
