"""Write a benchmark's generated block into a docs page, between its markers.

A page holds ``<!-- NAME:begin -->`` and ``<!-- NAME:end -->`` once each; :func:`write_block`
replaces what lies between them and leaves the rest of the page as it is. The benchmarks that
publish a headline figure use it (``benchmark_shipped.py`` into ``docs/benchmark.md``,
``bench_env_ratio.py`` and ``bench_vector_envs.py`` into ``docs/results/speed.md``), so that the
figure on the page is the one the benchmark printed, with the date and the machine beside it.
"""

from __future__ import annotations

import datetime
import os
import platform
import shlex
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
RESULTS = ROOT / "docs" / "results"


def markers(name: str) -> tuple[str, str]:
    """The begin and end markers of the block ``name``."""
    return f"<!-- {name}:begin -->", f"<!-- {name}:end -->"


def write_block(doc: Path, name: str, lines: list[str]) -> None:
    """Replace the block ``name`` of ``doc`` with ``lines`` (the markers stay). Refuses a page
    without exactly one pair of the block's markers, so a renamed page fails loudly."""
    begin, end = markers(name)
    text = doc.read_text(encoding="utf-8")
    if text.count(begin) != 1 or text.count(end) != 1 or text.index(begin) > text.index(end):
        raise SystemExit(f"{doc}: needs one {begin} ... {end} pair to write the table into")
    head, rest = text.split(begin)
    _, tail = rest.split(end)
    doc.write_text(head + begin + "\n" + "\n".join(lines) + "\n" + end + tail, encoding="utf-8")
    print(f"wrote the {name} block of {doc.relative_to(ROOT) if doc.is_relative_to(ROOT) else doc}")


def command_line() -> str:
    """How this script was run, as a command to copy (the path relative to the repository)."""
    script = Path(sys.argv[0]).resolve()
    name = script.relative_to(ROOT) if script.is_relative_to(ROOT) else script
    return " ".join(["python", str(name), *map(shlex.quote, sys.argv[1:])])


def cpu_name() -> str:
    """The CPU's model name (``platform.processor()`` is often empty on Linux)."""
    try:
        info = Path("/proc/cpuinfo").read_text(encoding="utf-8").splitlines()
        return next(line.split(":", 1)[1].strip() for line in info if line.startswith("model name"))
    except (OSError, StopIteration):
        return platform.processor() or platform.machine()


def machine_short() -> str:
    """The date and the core count, for a headline."""
    date = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d")
    return f"{date}, {os.cpu_count()} CPUs"


def machine(load_before: float) -> str:
    """The date and the machine, with the load around the run (others may share the cores)."""
    cpu = cpu_name()
    date = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    return (
        f"{date}; {cpu}, {os.cpu_count()} CPUs, Python {platform.python_version()}; "
        f"1-minute load average {load_before:.1f} at the start and {os.getloadavg()[0]:.1f} at "
        "the end"
    )
