"""scripts/tools/lowest_versions.py: the constraints CI's lowest-versions step installs are the
floors written in pyproject.toml (extras followed through self-references, torch left out)."""

from __future__ import annotations

import pytest

from tests.conftest import script_module

lowest_versions = script_module("tools/lowest_versions.py")

PYPROJECT = """
[project]
name = "pkg"
dependencies = ["numpy>=1.26", "scipy>=1.11,<2", "torch>=2.3", "old; python_version < '3.0'"]
[project.optional-dependencies]
rl = ["stable-baselines3>=2.7"]
test = ["pytest>=8", "pkg[rl]", "exact==1.2.3"]
loose = ["anything"]
"""


def test_pins_are_the_floors_of_the_core_and_the_chosen_extras(tmp_path):
    path = tmp_path / "pyproject.toml"
    path.write_text(PYPROJECT, encoding="utf-8")
    assert lowest_versions.lowest_pins([], path) == ["numpy==1.26", "scipy==1.11"]
    assert lowest_versions.lowest_pins(["test"], path) == [
        "exact==1.2.3",
        "numpy==1.26",
        "pytest==8",
        "scipy==1.11",
        "stable-baselines3==2.7",  # through pkg[rl]
    ]
    with pytest.raises(SystemExit, match="anything has no lower bound"):
        lowest_versions.lowest_pins(["loose"], path)
    with pytest.raises(SystemExit, match="unknown extra 'nope'"):
        lowest_versions.lowest_pins(["nope"], path)


def test_the_projects_own_floors_pin_every_direct_dependency_but_torch():
    pins = dict(pin.split("==") for pin in lowest_versions.lowest_pins(["rl", "test"]))
    assert "torch" not in pins and pins["gymnasium"] == "1.2.2" and pins["pymunk"].startswith("7")
