"""Peak memory and time of ``sfw-gym map`` on a long log in the SfW 2-router layout.

    python scripts/benchmarks/bench_map_log.py [--rows 1000000]

Writes a synthetic log of ``--rows`` rows (a random walk in a 40 m x 30 m building, canvas pixels
of 0.0115 m, the four band columns and the strongest as the unnamed 7th), then runs ``sfw-gym
map`` on it in a child process and prints the file size, the child's peak resident memory and
its wall time.

Results: docs/results/mapping.md#what-mapping-costs.
"""

from __future__ import annotations

import argparse
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

PX_M = 0.0115


def write_log(path: Path, rows: int) -> None:
    rng = np.random.default_rng(0)
    steps = rng.normal(0.0, 0.05, (rows, 2))
    xy = np.abs(np.cumsum(steps, axis=0) % np.array([80.0, 60.0]) - [40.0, 30.0]) + 1.0
    routers = np.array([[5.0, 5.0], [35.0, 25.0]])
    cols = []
    for r in routers:
        d = np.maximum(np.hypot(*(xy - r).T), 0.1)
        for offset in (0.0, -7.0):
            cols.append(np.round(-20.0 + offset - 20 * np.log10(d) + rng.normal(0, 2, rows)))
    rssi = np.column_stack(cols)
    table = np.column_stack([np.round(xy / PX_M, 1), rssi, rssi.max(axis=1)])
    with open(path, "w", encoding="utf-8-sig", newline="") as fh:
        fh.write("x_pixel,y_pixel,router1_2.4,router1_5,router2_2.4,router2_5,\r\n")
        np.savetxt(
            fh,
            table,
            fmt=["%.1f", "%.1f", "%d", "%d", "%d", "%d", "%d"],
            delimiter=",",
            newline="\r\n",
        )


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--rows", type=int, default=1_000_000)
    args = p.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        log = Path(tmp) / "long.csv"
        write_log(log, args.rows)
        routers = f"{5 / PX_M:.1f},{5 / PX_M:.1f};{35 / PX_M:.1f},{25 / PX_M:.1f}"
        argv = [
            sys.executable,
            "-m",
            "sfw_gym.cli",
            "map",
            str(log),
            "--routers",
            routers,
            "--px-per-m",
            str(1 / PX_M),
            "--resolution",
            "0.1",
            "--out",
            f"{tmp}/m.png",
        ]
        start = time.perf_counter()
        subprocess.run(argv, check=True, stdout=subprocess.DEVNULL)
        wall = time.perf_counter() - start
        peak_mib = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
        size_mib = log.stat().st_size / 2**20
    print(f"{args.rows:,} rows ({size_mib:.0f} MiB): peak RSS {peak_mib:.0f} MiB, {wall:.0f} s")


if __name__ == "__main__":
    main()
