"""``sfw-gym bench``: env steps/s and reset time beside CartPole-v1 (and MiniGrid), same run."""

from __future__ import annotations

import os
import platform
import resource
import statistics
import time
from dataclasses import dataclass

import gymnasium as gym
import numpy as np


@dataclass
class EnvTiming:
    """Throughput of one env: random actions through ``gym.make`` (wrappers included)."""

    env_id: str
    steps_per_s: float
    reset_ms: float


def time_env(env_id: str, steps: int, resets: int, seed: int = 0, **kwargs) -> EnvTiming:
    """Plain timing: ``steps`` random steps (resetting at episode ends), ``resets``
    resets. Actions are sampled before timing so that only the env is measured."""
    env = gym.make(env_id, **kwargs)
    env.reset(seed=seed)
    env.action_space.seed(seed)
    actions = [env.action_space.sample() for _ in range(steps)]
    for action in actions[:50]:  # warm-up: compiled kernels, caches
        if any(env.step(action)[2:4]):
            env.reset()
    start = time.perf_counter()
    for action in actions:
        _, _, terminated, truncated, _ = env.step(action)
        if terminated or truncated:
            env.reset()
    steps_per_s = steps / (time.perf_counter() - start)
    reset_times = []
    for _ in range(resets):
        start = time.perf_counter()
        env.reset()
        reset_times.append((time.perf_counter() - start) * 1e3)
    env.close()
    return EnvTiming(env_id, steps_per_s, statistics.median(reset_times))


def current_rss_mib() -> float:
    """Current resident set size, MiB (Linux /proc; elsewhere the peak so far)."""
    try:
        with open("/proc/self/statm") as fh:
            return int(fh.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20
    except OSError:
        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def memory_run(env_id: str, steps: int, seed: int = 0) -> tuple[float, float, int]:
    """RSS before and after ``steps`` random steps with resets (MiB), and the episodes run."""
    env = gym.make(env_id)
    env.reset(seed=seed)
    env.action_space.seed(seed)
    for _ in range(200):
        if any(env.step(env.action_space.sample())[2:4]):
            env.reset()
    before = current_rss_mib()
    episodes = 0
    for _ in range(steps):
        _, _, terminated, truncated, _ = env.step(env.action_space.sample())
        if terminated or truncated:
            env.reset()
            episodes += 1
    after = current_rss_mib()
    env.close()
    return before, after, episodes


def run_bench(env_id: str, steps: int, resets: int, memory_steps: int = 0) -> list[str]:
    """Measure and return printable lines (also the BENCHMARKS.md rows)."""
    load_before = os.getloadavg()[0]
    ours = time_env(env_id, steps, resets)
    ref = time_env("CartPole-v1", steps, resets)
    rows = [ours, ref]
    try:
        import minigrid  # noqa: F401

        rows.append(time_env("MiniGrid-Empty-8x8-v0", steps, resets))
    except ImportError:
        pass
    lines = [f"{'env':<28} {'steps/s':>10} {'reset ms':>9} {'steps/s ratio':>14}"]
    for r in rows:
        ratio = ours.steps_per_s / r.steps_per_s
        lines.append(f"{r.env_id:<28} {r.steps_per_s:>10,.0f} {r.reset_ms:>9.2f} {ratio:>13.3f}x")
    lines.append(f"(ratio = {env_id} steps/s ÷ that env's; {steps} random steps, {resets} resets)")
    lines.append(
        f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} CPUs; "
        f"1-min load average {load_before:.2f} before, {os.getloadavg()[0]:.2f} after"
    )
    if memory_steps:
        before, after, episodes = memory_run(env_id, memory_steps)
        lines.append(
            f"memory: RSS {before:.1f} MiB before, {after:.1f} MiB after {memory_steps:,} steps "
            f"({episodes} episodes): {after - before:+.1f} MiB"
        )
    return lines


def main_bench(env_id: str, steps: int, resets: int, memory_steps: int) -> int:
    """Entry of ``sfw-gym bench``."""
    import sfw_gym  # noqa: F401  (registration)

    np.set_printoptions(precision=3)
    for line in run_bench(env_id, steps, resets, memory_steps):
        print(line)
    return 0
