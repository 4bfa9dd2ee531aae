"""Time ICP scan matching and measure its basin (issue 18: <= 5 ms per pair of 360-point scans).

    python scripts/benchmarks/bench_icp.py [--trials 100] [--seed 0]

Synthetic scans of an L-shaped room (10 m x 8 m, exact ray casting, 12 m range, 1 cm range
noise), 360 and 600 beams over 360°. Each trial: a random pose A in the room, pose B 0.5 m and
up to 15° away, ICP from the true delta off by the given translation (random direction) and
rotation (random sign). Prints, per beams × method × initial error: ms per ICP, the success
rate (error < 5 cm and < 0.5°), the paper's acceptance rate, and the median error of the
successes.

Results: docs/results/slam.md#radiolidar-slam.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from sfw_gym.slam.pose_graph import compose_pose, relative_pose
from sfw_gym.slam.scan_matching import IcpConfig, icp

ROOM = np.array([(0, 0), (10, 0), (10, 4), (4, 4), (4, 8), (0, 8)], np.float64)
MAX_RANGE_M = 12.0
NOISE_M = 0.01
ERRORS = [(0.1, 5.0), (0.3, 10.0), (0.5, 20.0)]  # initial errors: metres, degrees


def cast(pose: np.ndarray, beams: int, rng: np.random.Generator) -> np.ndarray:
    """The scan ``(M, 2)`` in the robot's frame from ``pose`` (beams that hit within range)."""
    p0, p1 = ROOM, np.roll(ROOM, -1, axis=0)
    angles = np.linspace(0.0, 2 * math.pi, beams, endpoint=False)
    d = np.column_stack([np.cos(angles + pose[2]), np.sin(angles + pose[2])])[:, None, :]
    e = (p1 - p0)[None]
    w = (p0 - pose[:2])[None]
    cross = d[..., 0] * e[..., 1] - d[..., 1] * e[..., 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (w[..., 0] * e[..., 1] - w[..., 1] * e[..., 0]) / cross
        u = (w[..., 0] * d[..., 1] - w[..., 1] * d[..., 0]) / cross
    t = np.where((t > 0) & (u >= 0) & (u <= 1), t, np.inf).min(axis=1)
    hit = t < MAX_RANGE_M
    r = t[hit] + rng.normal(0.0, NOISE_M, hit.sum())
    return np.column_stack([r * np.cos(angles[hit]), r * np.sin(angles[hit])])


def random_pose(rng: np.random.Generator) -> np.ndarray:
    """A pose at least 0.5 m inside the room's walls."""
    x, y = (
        (rng.uniform(0.5, 9.5), rng.uniform(0.5, 3.5))
        if rng.random() < 0.6
        else (
            rng.uniform(0.5, 3.5),
            rng.uniform(0.5, 7.5),
        )
    )
    return np.array([x, y, rng.uniform(-math.pi, math.pi)])


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--trials", type=int, default=100)
    p.add_argument("--seed", type=int, default=0)
    args = p.parse_args()
    print(f"{'beams':>5} {'method':>14} {'init err':>10} {'ms/ICP':>7} {'success':>8} "
          f"{'accepted':>8} {'med err mm':>10} {'med err mrad':>12}")  # fmt: skip
    for beams in (360, 600):
        for method in ("point_to_line", "point_to_point"):
            cfg = IcpConfig(method=method)
            for err_m, err_deg in ERRORS:
                rng = np.random.default_rng(args.seed)
                elapsed, ok, accepted, errs = 0.0, 0, 0, []
                for _ in range(args.trials):
                    pose_a = random_pose(rng)
                    step = rng.uniform(-math.pi, math.pi)
                    move = (0.5 * math.cos(step), 0.5 * math.sin(step), rng.uniform(-0.26, 0.26))
                    pose_b = compose_pose(pose_a, move)
                    a, b = cast(pose_a, beams, rng), cast(pose_b, beams, rng)
                    truth = np.array(relative_pose(pose_a, pose_b))
                    off = rng.uniform(-math.pi, math.pi)
                    sign = rng.choice((-1.0, 1.0))
                    guess = truth + np.array(
                        [err_m * math.cos(off), err_m * math.sin(off), sign * math.radians(err_deg)]
                    )
                    start = time.perf_counter()
                    result = icp(a, b, guess, cfg)
                    elapsed += time.perf_counter() - start
                    miss = result.delta - truth
                    miss_m, miss_rad = math.hypot(*miss[:2]), abs(miss[2])
                    if miss_m < 0.05 and miss_rad < math.radians(0.5):
                        ok += 1
                        errs.append((miss_m, miss_rad))
                    accepted += result.accepted(len(a), len(b), cfg)
                med = np.median(errs, axis=0) if errs else (math.nan, math.nan)
                print(
                    f"{beams:>5} {method:>14} {err_m:>4} m {err_deg:>2.0f}° "
                    f"{1e3 * elapsed / args.trials:>7.2f} {ok / args.trials:>8.0%} "
                    f"{accepted / args.trials:>8.0%} {1e3 * med[0]:>10.1f} {1e3 * med[1]:>12.2f}"
                )


if __name__ == "__main__":
    main()
