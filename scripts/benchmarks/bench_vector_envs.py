"""Env steps/s of N SfW envs: the native vector env (``gym.make_vec``'s default) beside
Gymnasium's ``SyncVectorEnv`` and ``AsyncVectorEnv``, each as a multiple of one env's steps/s
measured in the same run; and P processes each stepping a native N-env batch at once (issue 33).

With ``--rounds R`` it times only one env and the native N-env batch, alternately in R rounds,
and prints the median of the per-round ratios (a neighbour's load hits both sides of a round);
``--against DIR`` times the code in DIR (say, a worktree of an older commit) in the same rounds.

    python scripts/benchmarks/bench_vector_envs.py --env SfW-Explore-v0 --num-envs 16 --steps 200
    python scripts/benchmarks/bench_vector_envs.py --floorplan ../shared/floorplans/houseexpo/P.json
    python scripts/benchmarks/bench_vector_envs.py --rounds 15 --steps 150 --clock cpu \
        --against /tmp/before
    python scripts/benchmarks/bench_vector_envs.py --rounds 15 --steps 150 --clock cpu --write-docs
    python scripts/benchmarks/bench_vector_envs.py --steps 200 --write-docs

Results: docs/results/speed.md#the-native-vector-env (the headline "16 native envs ÷ one env"
figure). ``--write-docs`` writes the table, with the command, the date and the machine, into
that page: the ``--rounds`` run between ``<!-- bench_vector_envs:begin -->`` and
``<!-- bench_vector_envs:end -->``, the run without ``--rounds`` (every vectorisation beside
one env) between ``<!-- bench_vector_envs_table:begin -->`` and ``:end -->``.
"""

from __future__ import annotations

import argparse
import multiprocessing
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import gymnasium as gym
from _docs import RESULTS, command_line, machine, machine_short, write_block

import sfw_gym  # noqa: F401  (registers the ids)

DOC = RESULTS / "speed.md"
HEADLINE = "<!-- bench_vector_envs:headline -->"


def env_steps_per_s(
    env: gym.Env | gym.vector.VectorEnv, steps: int, batch: int, clock: Any = time.perf_counter
) -> float:
    """Env steps per second of ``clock`` over ``steps`` calls of random actions (after a
    warm-up)."""
    env.reset(seed=0)
    env.action_space.seed(0)
    actions = [env.action_space.sample() for _ in range(steps + 20)]
    for action in actions[:20]:
        env.step(action)
    start = clock()
    for action in actions[20:]:
        out = env.step(action)
        if batch == 1 and (out[2] or out[3]):
            env.reset()
    rate = steps * batch / (clock() - start)
    env.close()
    return rate


def _native_rate(job: tuple[str, int, int, dict[str, Any], Any]) -> float:
    """One worker process of the P-process row: its native batch's env steps/s, timed after
    every worker is ready (``barrier``)."""
    env_id, n, steps, kwargs, barrier = job
    vec = gym.make_vec(env_id, num_envs=n, **kwargs)
    env_steps_per_s(vec, 20, n)  # compile and first resets outside the timing
    barrier.wait()
    return env_steps_per_s(gym.make_vec(env_id, num_envs=n, **kwargs), steps, n)


def _clock(name: str) -> Any:
    return time.process_time if name == "cpu" else time.perf_counter


def serve(env_id: str, n: int, steps: int, kwargs: dict[str, Any], clock_name: str) -> None:
    """A worker of ``--against``: for each line read ("one" or "vec"), time one env
    (``n * steps`` steps) or the native ``n``-env batch (``steps`` steps) and print its rate."""
    clock = _clock(clock_name)
    env_steps_per_s(gym.make_vec(env_id, num_envs=n, **kwargs), 20, n)  # warm-up
    print("ready", flush=True)
    for line in sys.stdin:
        if line.strip() == "one":
            rate = env_steps_per_s(gym.make(env_id, **kwargs), n * steps, 1, clock)
        else:
            rate = env_steps_per_s(gym.make_vec(env_id, num_envs=n, **kwargs), steps, n, clock)
        print(rate, flush=True)


def native_rounds(args: argparse.Namespace, kwargs: dict[str, Any]) -> None:
    """One env and the native batch timed alternately in ``args.rounds`` rounds, by this
    checkout and, with ``--against DIR``, by the code in DIR (two worker processes taking turns);
    prints the medians of the per-round rates and ratios."""
    worker = [sys.executable, __file__, "--serve", "--env", args.env, "--num-envs",
              str(args.num_envs), "--steps", str(args.steps), "--clock", args.clock]  # fmt: skip
    if args.floorplan:
        worker += ["--floorplan", args.floorplan]
    trees = {"this checkout": str(Path(__file__).resolve().parents[2])}
    if args.against:
        trees[f"against {args.against}"] = str(Path(args.against).resolve())
    workers = {
        name: subprocess.Popen(
            worker,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
            env={**os.environ, "PYTHONPATH": tree},
        )
        for name, tree in trees.items()
    }
    for w in workers.values():
        assert w.stdout is not None and w.stdout.readline().strip() == "ready"
    rates: dict[tuple[str, str], list[float]] = {(t, k): [] for t in trees for k in ("one", "vec")}
    for _ in range(args.rounds):
        for kind in ("one", "vec"):
            for name, w in workers.items():
                assert w.stdin is not None and w.stdout is not None
                w.stdin.write(kind + "\n")
                w.stdin.flush()
                rates[name, kind].append(float(w.stdout.readline()))
    for w in workers.values():
        assert w.stdin is not None
        w.stdin.close()
        w.wait()
    n = args.num_envs
    print(f"{args.env}: env steps per {args.clock} second, medians of {args.rounds} rounds")
    rows: list[str] = []
    headline = ""  # this checkout's
    for name in trees:
        one, vec = rates[name, "one"], rates[name, "vec"]
        ratios = [b / a for a, b in zip(one, vec, strict=True)]
        q = statistics.quantiles(ratios, n=4) if len(ratios) > 1 else ratios * 3
        print(
            f"  {name}: one env {statistics.median(one):,.0f}, {n} native "
            f"{statistics.median(vec):,.0f}; {n} native / one env {statistics.median(ratios):.2f}x "
            f"(quartiles {q[0]:.2f}-{q[-1]:.2f})"
        )
        rows.append(
            f"| {name} | {statistics.median(one):,.0f} | {statistics.median(vec):,.0f} | "
            f"**{statistics.median(ratios):.2f}×** ({q[0]:.2f}–{q[-1]:.2f}) |"
        )
        headline = headline or (
            f"**{n} native envs in one process ÷ one env: {statistics.median(ratios):.2f}×** "
            f"(median of {args.rounds} per-round ratios on the {args.clock} clock; quartiles "
            f"{q[0]:.2f}–{q[-1]:.2f}; {machine_short()})."
        )
    gains = []
    if args.against:
        this, other = trees
        for kind in ("one", "vec"):
            gain = [a / b for a, b in zip(rates[this, kind], rates[other, kind], strict=True)]
            print(f"  {kind}: this checkout / against, median {statistics.median(gain):.2f}x")
            gains.append(f"{kind}: {statistics.median(gain):.2f}×")
    if args.write_docs:
        clock = "the process's CPU time" if args.clock == "cpu" else "wall time"
        lines = [
            f"`{command_line()}`: {machine(args.load_before)}. {args.env}, random actions, "
            f"{args.rounds} rounds; in each, one env steps {n} × {args.steps:,} times and the "
            f"native {n}-env batch {args.steps:,} times, timed on {clock}. Other jobs may share "
            "the cores: the ratio, taken round by round, is the figure to compare.",
            "",
            f"| code | one env, steps/s | {n} native, steps/s | "
            f"{n} native ÷ one env, median (quartiles) |",
            "|---|---:|---:|---|",
            *rows,
        ]
        if gains:
            lines += ["", "This checkout ÷ the other, median per round: " + "; ".join(gains) + "."]
        lines += ["", HEADLINE, headline]  # docs/results/index.md includes the line after HEADLINE
        write_block(DOC, "bench_vector_envs", lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--env", default="SfW-Explore-v0")
    parser.add_argument("--num-envs", type=int, default=16)
    parser.add_argument("--steps", type=int, default=200, help="vector steps per measurement")
    parser.add_argument("--processes", type=int, default=2, help="processes of the last row")
    parser.add_argument("--floorplan", default=None, help="a plan file for every episode")
    parser.add_argument("--rounds", type=int, default=0, help="only one env vs native, R rounds")
    parser.add_argument(
        "--clock",
        choices=("wall", "cpu"),
        default="wall",
        help="with --rounds: wall time, or the process's CPU time (a machine others load)",
    )
    parser.add_argument("--against", default=None, help="with --rounds: the code in this dir too")
    parser.add_argument(
        "--write-docs",
        action="store_true",
        help="write the table into docs/results/speed.md (block bench_vector_envs, or "
        "bench_vector_envs_table without --rounds)",
    )
    parser.add_argument("--serve", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    args.load_before = os.getloadavg()[0]
    n, kwargs = args.num_envs, {} if args.floorplan is None else {"floorplan": args.floorplan}
    if args.rounds:
        native_rounds(args, kwargs)
        return
    env_steps_per_s(gym.make(args.env, **kwargs), 200, 1)  # warm-up: compiled kernels
    if args.serve:
        serve(args.env, n, args.steps, kwargs, args.clock)
        return
    one = env_steps_per_s(gym.make(args.env, **kwargs), args.steps, 1)
    rows = [("one env", one)]
    for mode, label in (("vector_entry_point", "native"), ("sync", "Gymnasium sync")):
        vec = gym.make_vec(args.env, num_envs=n, vectorization_mode=mode, **kwargs)
        rows.append((f"{n} envs, {label}", env_steps_per_s(vec, args.steps, n)))
    vec = gym.make_vec(args.env, num_envs=2, vectorization_mode="async", **kwargs)
    rows.append(("2 envs, Gymnasium async (2 processes)", env_steps_per_s(vec, args.steps * 2, 2)))
    p = args.processes
    context = multiprocessing.get_context("spawn")
    barrier = context.Manager().Barrier(p)
    with context.Pool(p) as pool:
        rates = pool.map(_native_rate, [(args.env, n, args.steps, kwargs, barrier)] * p)
    rows.append((f"{p} processes × {n} envs, native", sum(rates)))
    print(f"{args.env}: env steps/s, and as a multiple of one env's in this run")
    for name, rate in rows:
        print(f"  {name:34s} {rate:10,.0f}  {rate / one:5.2f}x")
    native = rows[1][1]
    print(f"  {p} processes / one process (native, {n} envs each): {sum(rates) / native:.2f}x")
    if args.write_docs:
        plan = f"every episode on `{args.floorplan}`" if args.floorplan else "procedural plans"
        lines = [
            f"`{command_line()}`: {machine(args.load_before)}. {args.env}, {plan}, random "
            f"actions, {args.steps:,} vector steps per row, wall time, one run. Other jobs may "
            "share the cores, and one run is one sample: read the rows against each other.",
            "",
            "| env steps/s | steps/s | × one env |",
            "|---|---:|---:|",
            *(f"| {name} | {rate:,.0f} | {rate / one:.2f}× |" for name, rate in rows),
            f"| {p} processes ÷ one process (native, {n} envs each) | | "
            f"{sum(rates) / native:.2f}× |",
        ]
        write_block(DOC, "bench_vector_envs_table", lines)


if __name__ == "__main__":
    main()
