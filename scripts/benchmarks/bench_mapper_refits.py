"""Mean µs per sample of SparseInverseKVisibility.update(), k-means refits included (issue 31).

The refits (1-D k-means of every router's features, on the geometric schedule: at 32 samples,
then every x1.5, at most 2000 apart) are rare but were slow (scikit-learn's KMeans: ~1 ms a call,
two calls a refit), so they set the mean while the median stayed near 8 µs. This times whole
surveys of 300, 3,000 and 30,000 samples through the old fit (scikit-learn) and the new one (the
compiled 1-D Lloyd of ``sfw_gym.mapping.k_estimation``), side by side in one run, and checks
that both give the same k-values, thresholds and map.

The world is ``bench_mapper_speed.py``'s: a 15 x 15 m two-room square, two routers, 10 dB per
wall, N(0, 2) dB noise rounded to integer dBm; a survey of N samples is the first N (5 cm apart)
of its lawnmower path (14,442 samples: left room, door, right room), walked back and forth as
often as N needs (so 300 samples see part of the left room, 30,000 both rooms twice). Before
timing, each fit path is warmed up as ``map_log`` does (``offline._warm_up``: compiled kernels
loaded, scikit-learn imported), so one-time costs stay out of the per-sample figures. Surveys
shorter than 30,000 samples are repeated (fresh mapper each time) to about 30,000 timed updates.

Usage: python scripts/benchmarks/bench_mapper_refits.py [--seed 0] [--sizes 300 3000 30000]
                                             [--min-updates 30000] [--policy strongest]

Results: docs/results/mapping.md#what-mapping-costs.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_mapper_speed import ROUTERS, SIDE_M, rssi_for, trajectory

from sfw_gym.mapping import (
    GridSpec,
    MapperConfig,
    SparseInverseKVisibility,
    k_estimation,
)
from sfw_gym.mapping.offline import _warm_up

BACKENDS = ("sklearn", "numba")  # old, new


def survey(n: int, seed: int, noise_db: float) -> tuple[np.ndarray, np.ndarray]:
    """The first ``n`` samples (5 cm apart) of the two-room lawnmower, surveyed back and forth
    as often as ``n`` needs, and their RSSI."""
    path = trajectory()
    loop = np.concatenate([path, path[-2:0:-1]])
    traj = np.resize(loop, (n, 2)) if n > loop.shape[0] else path[:n]
    rssi, _ = rssi_for(traj, np.random.default_rng(seed), noise_db)
    return traj, rssi


def run(config: MapperConfig, grid: GridSpec, traj: np.ndarray, rssi: np.ndarray):
    """One survey: (µs per update, k-values, final thresholds, occupancy, refits)."""
    mapper = SparseInverseKVisibility(grid, ROUTERS, config)
    n = traj.shape[0]
    times = np.empty(n)
    ks = np.empty((n, len(ROUTERS)), np.int64)
    clock = time.perf_counter_ns
    update = mapper.update
    for i in range(n):
        p = traj[i]
        r = rssi[i]
        t0 = clock()
        update(p, r)
        times[i] = (clock() - t0) / 1000.0
        ks[i] = mapper.last_k
    ke = mapper.k_estimator
    thr = [ke.thresholds(r) for r in range(len(ROUTERS))]
    return times, ks, thr, mapper.occupancy_u8.copy(), ke.n_refits


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--sizes", type=int, nargs="+", default=[300, 3000, 30000])
    ap.add_argument("--min-updates", type=int, default=30000, help="timed updates per size/path")
    ap.add_argument("--noise-db", type=float, default=2.0)
    ap.add_argument("--policy", default="strongest", choices=("strongest", "all"))
    args = ap.parse_args()

    config = MapperConfig(router_policy=args.policy)
    grid = GridSpec.covering((0.0, 0.0, SIDE_M, SIDE_M), 0.05, margin_m=0.2)
    saved = k_estimation.FIT_BACKEND
    try:
        for backend in BACKENDS:
            k_estimation.FIT_BACKEND = backend
            _warm_up(config)
        print(
            f"{args.policy} / {config.k_estimator}, {len(ROUTERS)} routers, grid "
            f"{grid.shape[0]}x{grid.shape[1]} @ 0.05 m; µs per update, refits included"
        )
        print(
            f"{'samples':>7s} {'refits':>6s} {'fit':>7s} {'mean':>7s} {'median':>7s} "
            f"{'p95':>7s} {'max':>8s}  same k / thresholds / map as sklearn"
        )
        ratio = {}
        for n in args.sizes:
            traj, rssi = survey(n, args.seed, args.noise_db)
            repeats = max(1, -(-args.min_updates // n))
            stats, outs = {}, {}
            # interleave the two paths, so load from other jobs hits both alike
            all_times: dict[str, list[np.ndarray]] = {b: [] for b in BACKENDS}
            for _ in range(repeats):
                for backend in BACKENDS:
                    k_estimation.FIT_BACKEND = backend
                    times, ks, thr, occ, refits = run(config, grid, traj, rssi)
                    all_times[backend].append(times)
                    outs[backend] = (ks, thr, occ, refits)
            for backend in BACKENDS:
                t = np.concatenate(all_times[backend])
                stats[backend] = (t.mean(), np.median(t))
                ks, thr, occ, refits = outs[backend]
                ref = outs[BACKENDS[0]]
                same = (
                    np.array_equal(ks, ref[0])
                    and all(np.array_equal(a, b) for a, b in zip(thr, ref[1], strict=True))
                    and np.array_equal(occ, ref[2])
                )
                print(
                    f"{n:7d} {refits:6d} {backend:>7s} {t.mean():7.2f} {np.median(t):7.2f} "
                    f"{np.percentile(t, 95):7.2f} {t.max():8.1f}  {'yes' if same else 'NO'}"
                )
            old, new = stats["sklearn"], stats["numba"]
            ratio[n] = (old[0] / new[0], old[1] / new[1])
        print("old / new (sklearn / numba):")
        for n, (rm, rmed) in ratio.items():
            print(f"{n:7d} samples: mean x{rm:.2f}, median x{rmed:.2f}")
    finally:
        k_estimation.FIT_BACKEND = saved


if __name__ == "__main__":
    main()
