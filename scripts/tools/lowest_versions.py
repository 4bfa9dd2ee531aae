"""Pins every direct dependency of the chosen extras at its lower bound, as pip constraints.

CI installs with these constraints in a fresh venv and runs the quick loop, so a floor in
pyproject.toml that the code outgrew fails there. torch is left out: its floor would pull the CUDA
build; the venv takes the CPU build that these machines carry (``torch==2.13.0``).

    python scripts/tools/lowest_versions.py rl test > lowest.txt
    pip install -c lowest.txt -e ".[rl,test]"
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import tomllib
from packaging.requirements import Requirement

PYPROJECT = Path(__file__).resolve().parents[2] / "pyproject.toml"
LEFT_OUT = {"torch"}  # see the module docstring


def lowest_pins(extras: list[str], pyproject: Path = PYPROJECT) -> list[str]:
    """``name==floor`` for the core dependencies and the extras' (self-references followed)."""
    project = tomllib.loads(pyproject.read_text())["project"]
    name, optional = project["name"], project.get("optional-dependencies", {})
    pins: dict[str, str] = {}
    todo, seen = list(extras), set()
    requirements = [Requirement(r) for r in project["dependencies"]]
    while todo:
        extra = todo.pop()
        if extra in seen:
            continue
        if extra not in optional:
            raise SystemExit(
                f"lowest_versions: unknown extra {extra!r} (known: {sorted(optional)})"
            )
        seen.add(extra)
        for req in map(Requirement, optional[extra]):
            if req.name == name:
                todo.extend(req.extras)
            else:
                requirements.append(req)
    for req in requirements:
        if req.name in LEFT_OUT or (req.marker and not req.marker.evaluate()):
            continue
        floors = [s.version for s in req.specifier if s.operator in (">=", "==", "~=")]
        if not floors:
            raise SystemExit(f"lowest_versions: {req} has no lower bound")
        pins[req.name] = max(
            floors, key=lambda v: tuple(int(p) for p in v.split(".") if p.isdigit())
        )
    return [f"{n}=={v}" for n, v in sorted(pins.items())]


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("extras", nargs="*", help="extras whose dependencies are pinned too")
    args = parser.parse_args(argv)
    sys.stdout.write("".join(f"{pin}\n" for pin in lowest_pins(args.extras)))


if __name__ == "__main__":
    main()
