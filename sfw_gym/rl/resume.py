"""Checkpoints that resume training exactly: a run killed and resumed ends with the same model as
one never interrupted.

SB3 saves the model (weights, optimiser, step count) but not what the next update depends on
besides: the envs mid-episode, the random generators (torch samples the actions, numpy shuffles
the minibatches), the last observation, the episode bookkeeping. Checkpoints are therefore taken
between PPO iterations (at the start of a rollout, when the rollout buffer is empty), and beside
each ``<algo>_<steps>_steps.zip`` goes ``<algo>_<steps>_steps.state.pkl`` with all of that; both
written atomically, the state first (a checkpoint without its state resumes as SB3 does: from
fresh episodes, not exactly).
"""

from __future__ import annotations

import logging
import pickle
import random
import warnings
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

from sfw_gym.core.atomic import atomic_path
from sfw_gym.core.errors import ConfigError

logger = logging.getLogger(__name__)


class Snapshots(gym.Wrapper):
    """The outermost wrapper of each training env: its whole state (inner wrappers, the env,
    its generator) as bytes, and back, also across SB3's worker processes (``env_method``)."""

    def snapshot(self) -> bytes:
        return pickle.dumps(self.env)

    def restore(self, blob: bytes) -> None:
        self.env = pickle.loads(blob)


def state_path(checkpoint: Path) -> Path:
    """Where the resume state of a ``…_steps.zip`` checkpoint lies."""
    return checkpoint.with_suffix(".state.pkl")


def resumable_checkpoints(
    every_steps: int, folder: Path, prefix: str, venv: Any, eval_venv: Any
) -> Any:
    """An SB3 callback that saves ``<prefix>_<steps>_steps.zip`` and its resume state at the
    first iteration boundary after every ``every_steps`` env steps (``venv``, ``eval_venv``: the
    training and evaluation ``VecMonitor``)."""
    from stable_baselines3.common.callbacks import BaseCallback

    class ResumableCheckpoints(BaseCallback):
        def _init_callback(self) -> None:
            self._saved_at = self.model.num_timesteps

        def _on_rollout_start(self) -> None:
            steps = self.model.num_timesteps
            if steps // every_steps > self._saved_at // every_steps:
                save_checkpoint(self.model, venv, eval_venv, folder / f"{prefix}_{steps}_steps.zip")
                self._saved_at = steps

        def _on_step(self) -> bool:
            return True

    return ResumableCheckpoints()


def save_checkpoint(model: Any, venv: Any, eval_venv: Any, path: Path) -> None:
    """The model at ``path`` and its resume state beside it (the state first, each atomic)."""
    import torch

    try:
        state = {
            "rng": (torch.get_rng_state(), np.random.get_state(), random.getstate()),  # noqa: NPY002 (SB3 shuffles with it)
            "last_obs": model._last_obs,
            "last_episode_starts": model._last_episode_starts,
            "ep_info_buffer": model.ep_info_buffer,
            "ep_success_buffer": model.ep_success_buffer,
            "envs": _venv_state(venv),
            "eval_envs": _venv_state(eval_venv),
        }
        blob = pickle.dumps(state)
    except (pickle.PicklingError, TypeError, AttributeError) as exc:
        warnings.warn(
            f"{path.name}: no resume state (an env does not pickle: {exc}); a resume from it "
            "starts fresh episodes",
            stacklevel=2,
        )
    else:
        with atomic_path(state_path(path)) as tmp:
            tmp.write_bytes(blob)
    with atomic_path(path) as tmp:
        model.save(tmp)
    logger.info("checkpoint %s", path)


def restore_state(model: Any, venv: Any, eval_venv: Any, checkpoint: Path) -> bool:
    """Put the resume state saved with ``checkpoint`` back into a model just loaded from it and
    into the freshly made envs; False when the checkpoint has none."""
    import torch

    path = state_path(checkpoint)
    if not path.is_file():
        return False
    try:
        state = pickle.loads(path.read_bytes())
        torch_rng, numpy_rng, python_rng = state["rng"]
    except (OSError, pickle.UnpicklingError, EOFError, KeyError, ValueError) as exc:
        raise ConfigError(f"{path}: cannot read the resume state ({exc})") from None
    _set_venv_state(venv, state["envs"])
    _set_venv_state(eval_venv, state["eval_envs"])
    model._last_obs = state["last_obs"]
    model._last_episode_starts = state["last_episode_starts"]
    model.ep_info_buffer = state["ep_info_buffer"]
    model.ep_success_buffer = state["ep_success_buffer"]
    torch.set_rng_state(torch_rng)
    np.random.set_state(numpy_rng)  # noqa: NPY002 (SB3 shuffles with it)
    random.setstate(python_rng)
    return True


def _venv_state(venv: Any) -> dict[str, Any]:
    """The envs of an SB3 ``VecMonitor(VecEnv)``, the monitor's running episodes, and the seeds
    and options still waiting for the next reset (an evaluation env is first reset at its first
    evaluation, which may come after a checkpoint)."""
    return {
        "envs": venv.env_method("snapshot"),
        "monitor": (venv.episode_returns, venv.episode_lengths, venv.episode_count),
        "next_reset": (list(venv.venv._seeds), list(venv.venv._options)),
    }


def _set_venv_state(venv: Any, state: dict[str, Any]) -> None:
    for i, blob in enumerate(state["envs"]):
        venv.env_method("restore", blob, indices=[i])
    venv.episode_returns, venv.episode_lengths, venv.episode_count = state["monitor"]
    # a state saved before the pending seeds were kept: the envs continue without them
    seeds, options = state.get("next_reset", ([None] * venv.num_envs, [{}] * venv.num_envs))
    venv.venv._seeds, venv.venv._options = list(seeds), list(options)
