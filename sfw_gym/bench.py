"""``sfw-gym bench``: env steps/s and reset time beside CartPole-v1 (and MiniGrid), same run;
with ``--agents``, agent episode times beside random actions on the same plans and seeds, the
cost of :func:`~sfw_gym.navigation.candidates.candidate_goals`, and how an agent episode's time
grows with its length."""

from __future__ import annotations

import os
import platform
import resource
import statistics
import time
from dataclasses import dataclass
from typing import Any

import gymnasium as gym
import numpy as np

#: Sub-envs of the native vector env that ``sfw-gym speed`` times beside one env.
VECTOR_ENVS = 16


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


def time_vector_env(env_id: str, num_envs: int, steps: int, seed: int = 0) -> float:
    """Env steps/s of ``num_envs`` sub-envs of the native vector env (``gym.make_vec``'s
    default: one process, the explore sub-envs stepped together), ``steps`` vector steps of
    random actions after a warm-up; its autoreset resets inside the timing."""
    vec = gym.make_vec(env_id, num_envs=num_envs)
    vec.reset(seed=seed)
    vec.action_space.seed(seed)
    actions = [vec.action_space.sample() for _ in range(steps + 20)]
    for action in actions[:20]:
        vec.step(action)
    start = time.perf_counter()
    for action in actions[20:]:
        vec.step(action)
    rate = steps * num_envs / (time.perf_counter() - start)
    vec.close()
    return rate


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
    """Measure and return printable lines (also the rows of docs/results/speed.md)."""
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
    n = VECTOR_ENVS
    batch = time_vector_env(env_id, n, max(steps // n, 20))
    lines.append(
        f"{env_id} × {n} in one process (gym.make_vec): {batch:,.0f} env steps/s = "
        f"{batch / ours.steps_per_s:.2f}× one env"
    )
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


def time_agent_episode(agent: str, env_id: str, seed: int, **env_kwargs) -> tuple[float, int]:
    """Seconds and steps of one episode of ``agent`` (``"random"``: sampled actions) on
    ``env_id`` reset with ``seed``; env construction and reset are not timed."""
    from sfw_gym.agents import make_agent

    env = gym.make(env_id, **env_kwargs)
    obs, _ = env.reset(seed=seed)
    start = time.perf_counter()
    if agent == "random":
        env.action_space.seed(seed)
        act = lambda _obs: env.action_space.sample()  # noqa: E731
    else:
        a = make_agent(agent)
        a.reset(env, seed=seed)
        act = a.act
    steps, done = 0, False
    while not done:
        obs, _, terminated, truncated, _ = env.step(act(obs))
        steps += 1
        done = terminated or truncated
    seconds = time.perf_counter() - start
    env.close()
    return seconds, steps


def run_agent_bench(agents: list[str], env_ids: list[str], seeds: list[int]) -> list[str]:
    """Agent episodes beside random-action episodes, interleaved on the same plans and seeds."""
    for agent in ["random", *agents]:  # warm-up: compiled kernels, the PPO model's first load
        time_agent_episode(agent, env_ids[0], seeds[0], max_steps=50)
    lines = [
        f"{'env':<22} {'agent':<11} {'episode s':>10} {'steps':>7} {'ms/step':>8} "
        f"{'× random':>9} {'95% CI':>14}"
    ]
    for env_id in env_ids:
        times: dict[str, list[float]] = {a: [] for a in ["random", *agents]}
        steps: dict[str, list[int]] = {a: [] for a in times}
        for seed in seeds:
            for agent in times:
                t, n = time_agent_episode(agent, env_id, seed)
                times[agent].append(t)
                steps[agent].append(n)
        base = np.array(times["random"])
        for agent, ts in times.items():
            ratio = np.array(ts) / base
            half = 1.96 * ratio.std(ddof=1) / np.sqrt(len(ratio)) if len(ratio) > 1 else 0.0
            per_step = 1e3 * sum(ts) / sum(steps[agent])
            lines.append(
                f"{env_id:<22} {agent:<11} {np.mean(ts):>10.2f} {np.mean(steps[agent]):>7.0f} "
                f"{per_step:>8.3f} {ratio.mean():>8.2f}x {ratio.mean() - half:>6.2f}–"
                f"{ratio.mean() + half:.2f}"
            )
    lines.append(
        f"(× random: an agent's episode time ÷ the random-action episode's on the same seed, "
        f"mean over seeds {seeds[0]}–{seeds[-1]}; env construction and reset not timed)"
    )
    return lines


def synthetic_view(size: int, seed: int = 0):
    """A half-explored ``size``×``size`` belief of a generated plan: the truth within 45 % of
    the map's width of the plan's centre, unknown beyond (for timing map analysis)."""
    from sfw_gym.core.constants import U8_FREE, U8_UNKNOWN
    from sfw_gym.mapping.grid import GridSpec
    from sfw_gym.navigation.view import RobotView
    from sfw_gym.world import generate_floorplan

    plan = generate_floorplan(seed)
    xmin, ymin, xmax, ymax = plan.footprint.bounds
    truth, origin = plan.rasterize(max(xmax - xmin, ymax - ymin) / size)
    res = max(xmax - xmin, ymax - ymin) / size
    belief = np.full((size, size), U8_UNKNOWN, np.uint8)
    h, w = min(size, truth.shape[0]), min(size, truth.shape[1])
    belief[:h, :w] = truth[:h, :w]
    rows, cols = np.mgrid[0:size, 0:size]
    free = np.argwhere(belief == U8_FREE)
    centre = free[len(free) // 2]
    belief[np.hypot(rows - centre[0], cols - centre[1]) > 0.45 * size] = U8_UNKNOWN
    grid = GridSpec(origin, res, (size, size))
    xy = grid.cell_to_world(centre)
    return RobotView.hand_made(belief, grid, (xy[0], xy[1], 0.0), np.array([xy, xy + 1.0]))


def run_candidate_bench(sizes: tuple[int, ...] = (64, 256), calls: int = 30) -> list[str]:
    """Median and p95 of one candidate-goal menu (K = 32, its shortest-path field included):
    ``candidate_goals(view)`` from scratch, and a :class:`GoalFinder` kept across calls as the
    agents keep it (the router model and the distance to walls cached)."""
    from sfw_gym.navigation.candidates import GoalFinder, candidate_goals
    from sfw_gym.navigation.planning import cost_field

    def kept(finder: GoalFinder, view: Any) -> Any:
        paths = cost_field(finder.costs(view), view.cell, view.grid.resolution_m)
        return finder.find(view, paths, max_candidates=32)

    lines = [f"{'belief grid':<12} {'call':<22} {'candidates':>10} {'median ms':>10} {'p95 ms':>8}"]
    for size in sizes:
        view = synthetic_view(size)
        finder = GoalFinder()
        finder.reset(view)
        for label, call in (
            ("candidate_goals(view)", lambda v: candidate_goals(v, max_candidates=32)),
            ("GoalFinder, kept", lambda v, f=finder: kept(f, v)),
        ):
            menu = call(view)  # warm-up (compilation, caches)
            ms = []
            for _ in range(calls):
                start = time.perf_counter()
                call(view)
                ms.append(1e3 * (time.perf_counter() - start))
            lines.append(
                f"{f'{size}×{size}':<12} {label:<22} {len(menu):>10} {np.median(ms):>10.2f} "
                f"{np.percentile(ms, 95):>8.2f}"
            )
    return lines


def run_length_bench(agent: str, seed: int = 0, lengths: tuple[int, ...] = (3000, 30000)):
    """``agent``'s time per step on ``SfW-ExploreFull-v0`` at episode lengths ``lengths`` (the
    coverage target off, so each episode runs its whole budget)."""
    lines = [f"{'steps':>7} {'episode s':>10} {'ms/step':>8}"]
    for n in lengths:
        t, steps = time_agent_episode(
            agent,
            "SfW-ExploreFull-v0",
            seed,
            max_steps=n,
            steps_per_m2=1e5,
            coverage_target=1.0,
        )
        lines.append(f"{steps:>7} {t:>10.2f} {1e3 * t / steps:>8.3f}")
    return lines


def main_bench(
    env_id: str,
    steps: int,
    resets: int,
    memory_steps: int,
    agents: list[str] | None = None,
    episodes: int = 3,
) -> int:
    """Entry of ``sfw-gym bench``."""
    import sfw_gym  # noqa: F401  (registration)

    np.set_printoptions(precision=3)
    for line in run_bench(env_id, steps, resets, memory_steps):
        print(line)
    if agents:
        seeds = list(range(2_000_000, 2_000_000 + episodes))
        print()
        for line in run_agent_bench(agents, [env_id, "SfW-ExploreFull-v0"], seeds):
            print(line, flush=True)
        print("\ncandidate_goals(view) per call, shortest-path field included:")
        for line in run_candidate_bench():
            print(line)
        print(f"\n{agents[0]} on SfW-ExploreFull-v0, seed 0, by episode length:")
        for line in run_length_bench(agents[0]):
            print(line)
    return 0
