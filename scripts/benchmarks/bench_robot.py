"""Benchmark `sfw_gym.world.robot.Robot.step`: control steps per second in synthetic apartments.

Usage: ``python scripts/benchmarks/bench_robot.py [--steps 20000] [--repeats 3]``

The plans are n x n grids of rooms in a square box, separated by 0.1 m thick walls (each wall piece
a closed 4-segment outline) with a 0.9 m doorway in every wall; n = 3 gives 100 segments, n = 5
gives 324. A bump-aware random walk drives the robot (full speed ahead, random turns, back off and
turn after a bump), so a realistic share of steps is spent in wall contact. For scale, the same run
measures CartPole-v1 through ``gym.make`` when gymnasium is installed.

Results: docs/results/speed.md#the-simulated-worlds-parts.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from sfw_gym.world.robot import Robot, RobotConfig


def grid_apartment(n_rooms: int, room_m: float = 4.0, wall_m: float = 0.1, door_m: float = 0.9):
    """Walls (E, 4) of an n x n grid of rooms with a doorway in each wall piece."""
    size = n_rooms * room_m
    walls = [[0, 0, size, 0], [size, 0, size, size], [size, size, 0, size], [0, size, 0, 0]]

    def rect(x0: float, y0: float, x1: float, y1: float) -> None:
        walls.extend([[x0, y0, x1, y0], [x1, y0, x1, y1], [x1, y1, x0, y1], [x0, y1, x0, y0]])

    for i in range(1, n_rooms):
        c = i * room_m - wall_m / 2
        for j in range(n_rooms):
            lo, hi = j * room_m, (j + 1) * room_m
            mid = (lo + hi) / 2
            for a, b in ((lo, mid - door_m / 2), (mid + door_m / 2, hi)):
                rect(c, a, c + wall_m, b)  # vertical wall piece
                rect(a, c, b, c + wall_m)  # horizontal wall piece
    return np.array(walls, dtype=float)


def bench_robot(walls: np.ndarray, steps: int, repeats: int, seed: int) -> tuple[float, float]:
    """Best steps/s over repeats, and the share of steps that bumped."""
    cfg = RobotConfig(odometry_translation_std=0.02, odometry_heading_std_rad=0.01)
    rng = np.random.default_rng(seed)
    turns = rng.uniform(-1.0, 1.0, steps) * cfg.max_angular_speed_rad_s
    best, bumped = 0.0, 0
    for _ in range(repeats):
        robot = Robot(walls, cfg, (2.0, 2.0, 0.3), np.random.default_rng(seed))
        bumped = 0
        backing = 0
        t0 = time.perf_counter()
        for k in range(steps):
            if backing:
                res = robot.step(-0.2, cfg.max_angular_speed_rad_s)
                backing -= 1
            else:
                res = robot.step(cfg.max_linear_speed_m_s, turns[k])
            if res.bumped:
                bumped += 1
                backing = backing or 3
        best = max(best, steps / (time.perf_counter() - t0))
    return best, bumped / steps


def bench_cartpole(steps: int) -> float | None:
    """CartPole-v1 steps/s through gym.make (None without gymnasium)."""
    try:
        import gymnasium as gym
    except ImportError:
        return None
    env = gym.make("CartPole-v1")
    env.reset(seed=0)
    t0 = time.perf_counter()
    for _ in range(steps):
        _, _, terminated, truncated, _ = env.step(env.action_space.sample())
        if terminated or truncated:
            env.reset()
    return steps / (time.perf_counter() - t0)


def main() -> None:
    """Print robot steps/s for two plan sizes, beside CartPole-v1."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=20_000)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()

    cartpole = bench_cartpole(args.steps)
    cfg = RobotConfig()
    print(
        f"Robot.step: {cfg.physics_substeps} pymunk substeps per {cfg.control_period_s} s step, "
        f"{args.steps} steps, best of {args.repeats}"
    )
    for n in (3, 5):
        walls = grid_apartment(n)
        rate, bump_share = bench_robot(walls, args.steps, args.repeats, args.seed)
        line = (
            f"  {len(walls):4d} wall segments: {rate:9,.0f} steps/s ({1e6 / rate:5.1f} us/step), "
            f"{bump_share:.0%} of steps bumped"
        )
        if cartpole:
            line += f"; {rate / cartpole:.2f}x CartPole-v1"
        print(line)
    if cartpole:
        print(f"  reference CartPole-v1 via gym.make: {cartpole:,.0f} steps/s")


if __name__ == "__main__":
    main()
