"""Shared fixtures: hand-made plans with answers computable by hand, and the HouseExpo files."""

from __future__ import annotations

import importlib.util
import os
import sys
from pathlib import Path
from types import ModuleType

if "PYTEST_XDIST_WORKER" in os.environ:
    # ``-n auto`` runs a worker per core: OpenMP and BLAS pools of a thread per core in every
    # worker would oversubscribe the cores (torch's threads spin while they wait). Set before
    # numpy and torch load; numba keeps its threads, so its parallel kernels still run threaded.
    for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(_var, "1")

import pytest
from shapely.geometry import Polygon

from sfw_gym.world.floorplan import Floorplan, floorplan_from_polygon

SHARED_DIR = Path(__file__).resolve().parents[1].parent / "shared"
HOUSEEXPO_DIR = SHARED_DIR / "floorplans" / "houseexpo"
#: The real WiFi datasets (../shared/datasets/README.md); tests that need them skip without them.
DATASETS_DIR = SHARED_DIR / "datasets"
SCRIPTS_DIR = Path(__file__).resolve().parents[1] / "scripts"


def script_module(relative: str) -> ModuleType:
    """The script ``scripts/<relative>`` imported as a module (registered in ``sys.modules``
    under its stem, as dataclasses need)."""
    path = SCRIPTS_DIR / relative
    spec = importlib.util.spec_from_file_location(path.stem, path)
    assert spec and spec.loader, path
    module = sys.modules[path.stem] = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """``episode`` tests (whole episodes, training, worker pools, the heavy ids' repeats) are
    ``slow`` too: ``pytest -m "not slow"`` is the quick loop, CI runs everything."""
    for item in items:
        if item.get_closest_marker("episode") is not None:
            item.add_marker(pytest.mark.slow)


def houseexpo_files() -> list[Path]:
    """The shared HouseExpo plans, or an empty list when ../shared is absent."""
    return sorted(HOUSEEXPO_DIR.glob("*.json")) if HOUSEEXPO_DIR.is_dir() else []


@pytest.fixture
def houseexpo_paths() -> list[Path]:
    paths = houseexpo_files()
    if not paths:
        pytest.skip(f"HouseExpo floorplans not found at {HOUSEEXPO_DIR} (../shared is absent)")
    return paths


def two_rooms_polygon(door: bool = True) -> Polygon:
    """10 × 5 m, a 0.1 m wall at x = 4.95–5.05 from the bottom up to y = 4 (a 1 m doorway above).

    Without the doorway the wall reaches the top and the plan is two separate rooms; as a single
    polygon that is only possible with the door, so ``door=False`` gives the left room only.
    """
    if not door:
        return Polygon([(0, 0), (4.95, 0), (4.95, 5), (0, 5)])
    return Polygon([(0, 0), (4.95, 0), (4.95, 4), (5.05, 4), (5.05, 0), (10, 0), (10, 5), (0, 5)])


@pytest.fixture
def two_rooms() -> Floorplan:
    return floorplan_from_polygon(two_rooms_polygon(), name="two-rooms")


@pytest.fixture
def open_hall() -> Floorplan:
    """20 × 10 m without interior walls."""
    return floorplan_from_polygon(Polygon([(0, 0), (20, 0), (20, 10), (0, 10)]), name="hall")
