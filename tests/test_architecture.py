"""The house rules: layers that data flows through one way, no import cycles, a type-checked
package, a core without torch, and package data that the wheel carries."""

from __future__ import annotations

import fnmatch
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest
import tomllib

REPO = Path(__file__).resolve().parents[1]


def test_layer_contracts_hold():
    """import-linter's contracts in pyproject.toml: the layers and "only rl imports torch"."""
    from importlinter.cli import lint_imports

    assert lint_imports(config_filename=str(REPO / "pyproject.toml"), no_cache=True) == 0


def test_no_import_cycle_between_modules():
    import grimp

    graph = grimp.build_graph("sfw_gym")
    cycles = []
    for importer in sorted(graph.modules):
        for imported in sorted(graph.find_modules_directly_imported_by(importer)):
            back = graph.find_shortest_chain(importer=imported, imported=importer)
            if back:
                cycles.append((importer, *back))
    assert not cycles, "import cycles:\n" + "\n".join(" → ".join(c) for c in cycles)


@pytest.mark.slow
def test_type_checker_is_clean():
    from mypy import api

    stdout, stderr, status = api.run(["--config-file", str(REPO / "pyproject.toml")])
    assert status == 0, stdout + stderr


def test_making_and_stepping_an_env_imports_no_torch():
    code = (
        "import sfw_gym, gymnasium as gym, sys; e = gym.make('SfW-Explore-v0'); e.reset(seed=0); "
        "e.step(e.action_space.sample()); import sfw_gym.agents, sfw_gym.evaluation; "
        "assert not {'torch', 'stable_baselines3', 'tensorboard'} & set(sys.modules)"
    )
    subprocess.run([sys.executable, "-c", code], check=True, cwd=REPO)


def test_every_data_file_the_package_reads_is_in_the_wheel():
    from sfw_gym.core import data

    patterns = tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["setuptools"][
        "package-data"
    ]["sfw_gym"]
    package = REPO / "sfw_gym"
    read = [
        data.DEFAULT_WAYPOINT_MODEL_DIR / "model.zip",
        data.DEFAULT_WAYPOINT_MODEL_DIR / "config.yml",
        data.DEFAULT_MODEL_DIR / "model.zip",
        data.DEFAULT_MODEL_DIR / "config.yml",
        data.DEFAULT_HYPERPARAMS,
        data.SCENARIOS,
    ]
    for path in read:
        assert path.is_file(), path
        rel = path.resolve().relative_to(package.resolve()).as_posix()
        assert any(fnmatch.fnmatch(rel, p) for p in patterns), f"{rel} is not package data"


def test_checkout_agents_and_envs_are_the_package_data_not_copies():
    for name in ("agents", "envs"):
        assert (REPO / name).resolve() == (REPO / "sfw_gym" / "data" / name).resolve()


def test_models_saved_under_the_old_policy_path_still_load():
    from sfw_gym.core.data import DEFAULT_WAYPOINT_MODEL_DIR
    from sfw_gym.rl.training import import_dotted

    with zipfile.ZipFile(DEFAULT_WAYPOINT_MODEL_DIR / "model.zip") as archive:
        assert b"sfw_gym.agents.waypoint_policy" in archive.read("data")  # pickled before the move
    from sfw_gym.rl.policy import WaypointPolicy

    assert import_dotted("sfw_gym.agents.waypoint_policy.WaypointPolicy") is WaypointPolicy
    from sfw_gym.rl import WaypointPPOAgent

    assert isinstance(WaypointPPOAgent().model.policy, WaypointPolicy)
