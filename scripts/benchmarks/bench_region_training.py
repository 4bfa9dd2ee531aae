"""Region-policy training throughput (issue 39): decisions per second of ``sfw-gym train
ppo_mask --env SfW-ExploreRegions-v0``, two code trees run alternately in one session, so a
neighbour's load falls on both alike.

    python scripts/benchmarks/bench_region_training.py --before /tmp/before --timesteps 600 \
        --rounds 3

Each run is ``sfw-gym train`` (``sfw_gym.cli.main``) in a fresh process whose ``PYTHONPATH`` is
the tree (started outside the repository, so that the tree, not the working directory, is
imported), with that tree's own ``ppo_mask.yml`` less its ``behaviour_cloning`` block and with no
critic warm-up (4 of a 30,000-decision run's 50 updates; a short run would be all warm-up, whose
updates skip the actor's backward pass): PPO (``model.learn``: rollouts and updates) on a fresh
policy. Two figures per run: decisions per second of the learn call's wall time (the run's
``config.yml``), and per second of its CPU time in the training process (``time.process_time``
around ``MaskablePPO.learn``), which a neighbour's load on a shared machine moves far less (with
``--vec-env subproc`` the workers' CPU is not in it). ``--before-args``/``--after-args`` add
``sfw-gym train`` options to one side (``--after-args "--vec-env subproc"``).

Results: docs/results/training.md#training-throughput.
"""

from __future__ import annotations

import argparse
import os
import shlex
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import yaml

ENV_ID = "SfW-ExploreRegions-v0"
REPO = Path(__file__).resolve().parents[2]


def hyperparams_without_cloning(tree: Path, out: Path) -> Path:
    """``tree``'s ppo_mask.yml without the region block's behaviour cloning and critic warm-up,
    written to ``out``."""
    table = yaml.safe_load((tree / "agents" / "hyperparams" / "ppo_mask.yml").read_text())
    block = table["sfw_gym"][ENV_ID]
    block.pop("behaviour_cloning", None)
    block.get("fine_tuning", {})["critic_warmup_updates"] = 0
    out.write_text(yaml.safe_dump(table))
    return out


#: The child: ``sfw-gym train`` with the learn call's CPU time written to the file in argv[1].
CHILD = """
import sys, time
from sb3_contrib import MaskablePPO
learn = MaskablePPO.learn
def timed(self, *args, **kwargs):
    start = time.process_time()
    try:
        return learn(self, *args, **kwargs)
    finally:
        open(sys.argv[1], "w").write(repr(time.process_time() - start))
MaskablePPO.learn = timed
from sfw_gym.cli import main
sys.exit(main(sys.argv[2:]))
"""


def run_training(tree: Path, timesteps: int, extra: list[str], work: Path) -> dict[str, float]:
    """One ``sfw-gym train`` of ``tree``'s code: decisions, the learn call's wall and CPU time,
    the process's wall time."""
    out = Path(tempfile.mkdtemp(dir=work))
    params = hyperparams_without_cloning(tree, out / "ppo_mask.yml")
    command = [
        sys.executable, "-c", CHILD, str(out / "learn_cpu_s"), "train", "ppo_mask", "--env", ENV_ID,
        "--timesteps", str(timesteps), "--hyperparams", str(params), "--out", str(out / "run"),
        "--no-progress", "--checkpoint-every", "10000000", "--eval-every", "10000000", *extra,
    ]  # fmt: skip
    env = {**os.environ, "PYTHONPATH": str(tree)}
    start = time.perf_counter()
    subprocess.run(command, cwd=work, env=env, check=True, stdout=subprocess.DEVNULL)
    process_s = time.perf_counter() - start
    summary = yaml.safe_load((out / "run" / "config.yml").read_text())
    return {
        "decisions": summary["steps"],
        "learn_s": summary["wall_time_s"],
        "learn_cpu_s": float((out / "learn_cpu_s").read_text()),
        "process_s": process_s,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", type=Path, required=True, help="the code before (a worktree)")
    parser.add_argument("--after", type=Path, default=REPO, help="the code after (default: here)")
    parser.add_argument("--timesteps", type=int, default=1200, help="decisions per run")
    parser.add_argument("--rounds", type=int, default=2, help="before/after pairs")
    parser.add_argument("--before-args", default="", help="extra sfw-gym train options")
    parser.add_argument("--after-args", default="", help="extra sfw-gym train options")
    args = parser.parse_args()
    sides = {
        "before": (args.before.resolve(), shlex.split(args.before_args)),
        "after": (args.after.resolve(), shlex.split(args.after_args)),
    }
    rates: dict[str, dict[str, list[float]]] = {n: {"wall": [], "cpu": []} for n in sides}
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(args.rounds):
            order = list(sides) if r % 2 == 0 else list(reversed(sides))
            for name in order:
                tree, extra = sides[name]
                got = run_training(tree, args.timesteps, extra, Path(tmp))
                wall, cpu = got["decisions"] / got["learn_s"], got["decisions"] / got["learn_cpu_s"]
                rates[name]["wall"].append(wall)
                rates[name]["cpu"].append(cpu)
                print(
                    f"round {r} {name:6s} {wall:6.2f} decisions/s, {cpu:6.2f} per CPU s "
                    f"({got['decisions']} in {got['learn_s']:.1f} s, CPU {got['learn_cpu_s']:.1f} "
                    f"s; process {got['process_s']:.1f} s; load {os.getloadavg()[0]:.1f})",
                    flush=True,
                )
    for kind in ("wall", "cpu"):
        for name in sides:
            values = " / ".join(f"{v:.2f}" for v in rates[name][kind])
            print(f"{name:6s} decisions per {kind} s: {values}")
        ratios = [a / b for a, b in zip(rates["after"][kind], rates["before"][kind], strict=True)]
        print(
            f"after ÷ before ({kind}), per round: "
            + " / ".join(f"{x:.2f}" for x in ratios)
            + f" (median {statistics.median(ratios):.2f})"
        )


if __name__ == "__main__":
    main()
