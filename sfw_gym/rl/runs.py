"""Where a training run keeps its model and its hyperparameters: rl-baselines3-zoo's layout,
which ``sfw-gym train`` writes and ``python -m rl_zoo3.enjoy`` reads::

    OUT/<env-id>.zip            the final model (``model.zip`` in runs from before 0.2.0)
    OUT/<env-id>/config.yml     the env id's block of the hyperparameter file, as rl-zoo keeps it
    OUT/<env-id>/args.yml       the run's arguments (algo, env, env_kwargs, seed, ...)
    OUT/config.yml              sfw-gym's record of the run (with the ``sfw_gym`` block's keys,
                                the command, steps and wall time); rl-zoo does not read it

In rl-zoo's log folder ``OUT`` is ``<folder>/<algo>/<env-id>_<n>``.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import yaml

from sfw_gym.core.atomic import write_text_atomic
from sfw_gym.core.errors import ConfigError

#: The model's name in runs saved before the rl-zoo layout (still read).
LEGACY_MODEL = "model.zip"


def env_name(env_id: str) -> str:
    """The env id as rl-zoo names files by it: ``module:Env-v0`` → ``Env-v0``, ``/`` → ``-``."""
    name = env_id.rpartition(":")[2].replace("/", "-")
    if not name:
        raise ConfigError(f"env id {env_id!r} names no env")
    return name


def model_path(out: str | Path, env_id: str) -> Path:
    """Where the final model of a run of ``env_id`` in ``out`` is saved: ``out/<env-id>.zip``."""
    return Path(out) / f"{env_name(env_id)}.zip"


def find_model(folder: str | Path) -> Path:
    """The final model of the run in ``folder``: ``<env-id>.zip``, the env id read from the run's
    ``config.yml``, the folder's rl-zoo name ``<env-id>_<n>`` or its ``<env-id>/config.yml``;
    else the ``model.zip`` of an older run."""
    folder = Path(folder)
    names = [f"{env_name(e)}.zip" for e in _env_ids(folder)] + [LEGACY_MODEL]
    for name in dict.fromkeys(names):
        if (folder / name).is_file():
            return folder / name
    raise ConfigError(f"{folder}: no model found (looked for {', '.join(dict.fromkeys(names))})")


def _env_ids(folder: Path) -> list[str]:
    ids = []
    record = folder / "config.yml"
    if record.is_file():
        try:
            env_id = (yaml.safe_load(record.read_text(encoding="utf-8")) or {}).get("env_id")
        except (yaml.YAMLError, AttributeError):
            env_id = None
        if isinstance(env_id, str):
            ids.append(env_id)
    match = re.fullmatch(r"(.+)_\d+", folder.name)
    if match:
        ids.append(match.group(1))
    if folder.is_dir():
        ids += sorted(p.parent.name for p in folder.glob("*/config.yml"))
    return ids


def write_zoo_params(
    out: str | Path, env_id: str, block: dict[str, Any], args: dict[str, Any]
) -> Path:
    """Write rl-zoo's ``out/<env-id>/config.yml`` (``block``: the env id's block of the
    hyperparameter file, as written there) and ``args.yml`` (``args``: rl-zoo's argument names;
    ``env_kwargs`` is the one ``rl_zoo3.enjoy`` reads, and replaces the block's with).
    Returns the folder."""
    folder = Path(out) / env_name(env_id)
    folder.mkdir(parents=True, exist_ok=True)
    write_text_atomic(folder / "config.yml", yaml.safe_dump(dict(block)))
    write_text_atomic(folder / "args.yml", yaml.safe_dump({"env_kwargs": None, **args}))
    return folder
