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

from sfw_gym.core import data

REPO = Path(__file__).resolve().parents[1]


#: The shipped trained agents' folders (rl-zoo's <algo>/<env-id>_<n>) and their env ids.
SHIPPED_MODELS = {
    data.DEFAULT_WAYPOINT_MODEL_DIR: "SfW-Explore-v0",
    data.DEFAULT_MODEL_DIR: "SfW-ExploreGoals-v0",
    data.DEFAULT_REGIONS_MODEL_DIR: "SfW-ExploreRegions-v0",
}


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


def test_every_module_says_its_job_in_a_docstring():
    import ast

    missing = [
        str(path.relative_to(REPO))
        for path in sorted((REPO / "sfw_gym").rglob("*.py"))
        if not ast.get_docstring(ast.parse(path.read_text(encoding="utf-8")))
    ]
    assert not missing, f"modules without a docstring: {missing}"


@pytest.mark.slow
def test_type_checker_is_clean():
    from mypy import api

    stdout, stderr, status = api.run(["--config-file", str(REPO / "pyproject.toml")])
    assert status == 0, stdout + stderr


@pytest.mark.episode
def test_making_and_stepping_an_env_imports_no_torch():
    code = (
        "import sfw_gym, gymnasium as gym, sys; e = gym.make('SfW-Explore-v0'); e.reset(seed=0); "
        "e.step(e.action_space.sample()); import sfw_gym.agents, sfw_gym.evaluation; "
        "assert not {'torch', 'stable_baselines3', 'tensorboard'} & set(sys.modules)"
    )
    subprocess.run([sys.executable, "-c", code], check=True, cwd=REPO)


def test_the_command_line_builds_its_parser_without_the_heavy_libraries():
    """``sfw-gym --help`` and a usage error answer at once: building the parser imports
    no scikit-learn, torch or evaluation stack (each subcommand imports what it runs)."""
    code = (
        "import sys; from sfw_gym.cli import build_parser; build_parser(); "
        "print(sorted({'sklearn', 'torch', 'stable_baselines3', 'sfw_gym.evaluation'} "
        "& set(sys.modules)))"
    )
    out = subprocess.run([sys.executable, "-c", code], check=True, cwd=REPO, capture_output=True)
    assert out.stdout.decode().strip() == "[]"


def test_every_data_file_the_package_reads_is_in_the_wheel():
    patterns = tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["setuptools"][
        "package-data"
    ]["sfw_gym"]
    package = REPO / "sfw_gym"
    read = [data.DEFAULT_HYPERPARAMS, data.SCENARIOS]
    read += [data.DEFAULT_PREDICTOR_DIR / "model.pt", data.DEFAULT_PREDICTOR_DIR / "config.json"]
    for folder, env_id in SHIPPED_MODELS.items():  # each with rl-zoo's files, for rl_zoo3.enjoy
        read += [folder / f"{env_id}.zip", folder / "config.yml"]
        read += [folder / env_id / "config.yml", folder / env_id / "args.yml"]
    for path in read:
        assert path.is_file(), path
        rel = path.resolve().relative_to(package.resolve()).as_posix()
        assert any(fnmatch.fnmatch(rel, p) for p in patterns), f"{rel} is not package data"


def test_checkout_agents_and_envs_are_the_package_data_not_copies():
    for name in ("agents", "envs"):
        assert (REPO / name).resolve() == (REPO / "sfw_gym" / "data" / name).resolve()


@pytest.mark.parametrize("folder", list(SHIPPED_MODELS), ids=lambda f: f.name)
def test_shipped_models_load_plainly_with_their_policies_where_they_live(folder):
    """No custom unpickler, no custom_objects: ``PPO.load`` / ``MaskablePPO.load`` as rl-zoo
    calls them; every class the model pickled is importable from the path it names."""
    pytest.importorskip("sb3_contrib")
    import yaml
    from sb3_contrib import MaskablePPO
    from stable_baselines3 import PPO

    env_id = SHIPPED_MODELS[folder]
    model_zip = folder / f"{env_id}.zip"
    with zipfile.ZipFile(model_zip) as archive:
        assert b"sfw_gym.agents.waypoint_policy" not in archive.read("data")  # the old path
    assert not (folder / "model.zip").exists()
    algo = {"ppo": PPO, "ppo_mask": MaskablePPO}[folder.parent.name]
    model = algo.load(model_zip, device="cpu")
    policy = yaml.safe_load((folder / env_id / "config.yml").read_text(encoding="utf-8"))["policy"]
    assert f"{type(model.policy).__module__}.{type(model.policy).__name__}" == policy
