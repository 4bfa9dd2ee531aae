"""The data shipped inside the package, read with :mod:`importlib.resources`.

``sfw_gym/data/`` holds rl-baselines3-zoo's layout: ``agents/hyperparams/<algo>.yml``,
``agents/<algo>/<env-id>_<n>/`` (a trained model and its ``config.yml``) and
``envs/scenarios.yml`` (the benchmarks' floorplan sets and seed splits). In a checkout the
top-level ``agents/`` and ``envs/`` are links to these folders, so there is one copy, and the
wheel carries it.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path
from typing import Any

import yaml

from sfw_gym.core.errors import ConfigError


def data_path(*parts: str) -> Path:
    """The file system path of ``sfw_gym/data/<parts>`` (the package is installed unzipped)."""
    return Path(str(resources.files("sfw_gym").joinpath("data", *parts)))


#: The earlier waypoint policy (``sfw-gym train ppo`` with its waypoint hyperparameters).
DEFAULT_WAYPOINT_MODEL_DIR = data_path("agents", "ppo", "SfW-Explore-v0_1")
#: The shipped PPO on the wheels (``sfw-gym train ppo --env SfW-Explore-v0``, from scratch):
#: rl-zoo's latest ``ppo`` run of ``SfW-Explore-v0``, so ``rl_zoo3.enjoy`` replays it.
DEFAULT_WHEELS_MODEL_DIR = data_path("agents", "ppo", "SfW-Explore-v0_2")
#: The shipped candidate-goal explorer (trained by ``sfw-gym train ppo_mask``).
DEFAULT_MODEL_DIR = data_path("agents", "ppo_mask", "SfW-ExploreGoals-v0_1")
#: The shipped region explorer (``sfw-gym train ppo_mask --env SfW-ExploreRegions-v0``).
DEFAULT_REGIONS_MODEL_DIR = data_path("agents", "ppo_mask", "SfW-ExploreRegions-v0_1")
#: The map predictor that ``predict-explore`` reads (``scripts/tools/train_predictor.py``).
DEFAULT_PREDICTOR_DIR = data_path("agents", "predictor")
#: PPO hyperparameters per env id (rl-zoo format).
DEFAULT_HYPERPARAMS = data_path("agents", "hyperparams", "ppo.yml")


def default_hyperparams(algo: str) -> Path:
    """rl-zoo's hyperparameter file of ``algo`` (``ppo``, ``ppo_mask``, ``rllib_ppo``)."""
    return data_path("agents", "hyperparams", f"{algo}.yml")


#: The benchmarks' floorplan sets and seed splits.
SCENARIOS = data_path("envs", "scenarios.yml")


def scenario(name: str) -> dict[str, Any]:
    """One entry of ``envs/scenarios.yml`` (e.g. ``"demo"``: its env seed and episodes)."""
    with SCENARIOS.open(encoding="utf-8") as fh:
        table = yaml.safe_load(fh)
    if name not in table:
        raise ConfigError(f"{SCENARIOS}: no scenario {name!r}; known: {sorted(table)}")
    return dict(table[name])
