"""stable-baselines3 on a Gymnasium vector env (by default the native SfW one): SB3's ``VecEnv``
interface, with SB3's autoreset (a finished sub-env is reset at once, its last observation in
``infos[i]["terminal_observation"]``)::

    venv = SB3VecEnv(gym.make_vec("SfW-ExploreSmall-v0", num_envs=8))
    PPO("MultiInputPolicy", venv).learn(10_000)
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import gymnasium as gym
import numpy as np
from stable_baselines3.common.vec_env.base_vec_env import VecEnv, VecEnvObs, VecEnvStepReturn

from sfw_gym.core.errors import ConfigError


def unbatch_infos(infos: dict[str, Any], n: int) -> list[dict[str, Any]]:
    """A vector env's batched infos (arrays and ``_key`` masks) as one dict per sub-env."""
    out: list[dict[str, Any]] = [{} for _ in range(n)]
    for key, values in infos.items():
        if key.startswith("_"):
            continue
        present = infos.get(f"_{key}", np.ones(n, np.bool_))
        nested = unbatch_infos(values, n) if isinstance(values, dict) else None
        for i in np.flatnonzero(present).tolist():
            value = nested[i] if nested is not None else values[i]
            out[i][key] = value.item() if isinstance(value, np.generic) else value
    return out


class SB3VecEnv(VecEnv):
    """SB3's ``VecEnv`` over ``venv``, a Gymnasium vector env with ``NEXT_STEP`` autoreset
    that takes ``options={"reset_mask": ...}`` (the native SfW env, ``gym.make_vec``'s default
    for the SfW ids). With the same seed it gives what ``DummyVecEnv`` of single envs gives."""

    def __init__(self, venv: gym.vector.VectorEnv, action_repeat: int = 1) -> None:
        if (
            isinstance(action_repeat, bool)
            or not isinstance(action_repeat, int)
            or action_repeat < 1
        ):
            raise ConfigError(f"action_repeat must be an integer ≥ 1, got {action_repeat!r}")
        self.venv: Any = venv  # its get_attr and envs: the native env's
        self.action_repeat = action_repeat
        super().__init__(venv.num_envs, venv.single_observation_space, venv.single_action_space)
        self._actions: Any = None

    def reset(self) -> VecEnvObs:
        """Reset every sub-env with its seed and options (``seed()``, ``set_options()``):
        the sub-envs that share options in one call, through ``reset_mask``."""
        seeds = [None if s is None else int(s) for s in self._seeds]
        groups: list[tuple[dict[str, Any], list[int]]] = []
        for i, options in enumerate(self._options):
            group = next((g for g in groups if g[0] == (options or {})), None)
            if group is None:
                groups.append((dict(options or {}), [i]))
            else:
                group[1].append(i)
        obs: dict[str, np.ndarray] = {}
        self.reset_infos = [{} for _ in range(self.num_envs)]
        for options, members in groups:
            mask = np.zeros(self.num_envs, np.bool_)
            mask[members] = True
            obs, infos = self.venv.reset(seed=seeds, options={**options, "reset_mask": mask})
            for i, info in enumerate(unbatch_infos(infos, self.num_envs)):
                if mask[i]:
                    self.reset_infos[i] = info
        self._reset_seeds()
        self._reset_options()
        return obs  # the last call's batch holds every sub-env's first observation

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = actions

    def step_wait(self) -> VecEnvStepReturn:
        """One step of every sub-env, or ``action_repeat`` steps with the same actions (the
        rewards summed, as :class:`~sfw_gym.envs.action_repeat.ActionRepeat` does per env). A
        sub-env whose episode ends within the repeats is reset at once, as SB3 does; the repeats
        left step its new episode with the held action, their rewards not counted (episodes
        whose step budget is a multiple of the repeat end on a boundary)."""
        obs, rewards, dones, infos = self._step_once()
        ended = dones.copy()
        for _ in range(self.action_repeat - 1):
            obs, more, more_dones, more_infos = self._step_once()
            rewards += np.where(ended, 0.0, more).astype(np.float32)
            for i in range(self.num_envs):
                if not ended[i]:
                    infos[i] = more_infos[i]
            ended |= more_dones
        return obs, rewards, ended, infos

    def _step_once(self) -> VecEnvStepReturn:
        obs, rewards, terminated, truncated, batched = self.venv.step(self._actions)
        dones = terminated | truncated
        infos = unbatch_infos(batched, self.num_envs)
        for i, info in enumerate(infos):
            info["TimeLimit.truncated"] = bool(truncated[i] and not terminated[i])
        if dones.any():  # SB3 resets at once: the next observation is the new episode's first
            for i in np.flatnonzero(dones).tolist():
                infos[i]["terminal_observation"] = {key: rows[i] for key, rows in obs.items()}
            first, reset_batched = self.venv.reset(options={"reset_mask": dones})
            reset_infos = unbatch_infos(reset_batched, self.num_envs)
            obs = {key: rows.copy() for key, rows in obs.items()}
            for i in np.flatnonzero(dones).tolist():
                for key in obs:
                    obs[key][i] = first[key][i]
                self.reset_infos[i] = reset_infos[i]
        return obs, rewards.astype(np.float32), dones, infos

    def close(self) -> None:
        self.venv.close()

    def get_attr(self, attr_name: str, indices: Any = None) -> list[Any]:
        values = self.venv.get_attr(attr_name)
        return [values[i] for i in self._get_indices(indices)]

    def set_attr(self, attr_name: str, value: Any, indices: Any = None) -> None:
        for i in self._get_indices(indices):
            self.venv.envs[i].set_wrapper_attr(attr_name, value)

    def env_method(
        self, method_name: str, *method_args: Any, indices: Any = None, **method_kwargs: Any
    ) -> list[Any]:
        """Each sub-env's method; ``snapshot`` and ``restore`` (`sfw_gym.rl.resume`'s): the
        vector env's, which keep a sub-env's whole state as bytes."""
        if method_name in ("snapshot", "restore") and hasattr(self.venv, method_name):
            method = getattr(self.venv, method_name)
            return [method(i, *method_args, **method_kwargs) for i in self._get_indices(indices)]
        envs = self.venv.envs
        return [
            envs[i].get_wrapper_attr(method_name)(*method_args, **method_kwargs)
            for i in self._get_indices(indices)
        ]

    def env_is_wrapped(self, wrapper_class: type, indices: Any = None) -> list[bool]:
        from stable_baselines3.common import env_util

        envs = self.venv.envs
        return [env_util.is_wrapped(envs[i], wrapper_class) for i in self._get_indices(indices)]

    def get_images(self) -> Sequence[np.ndarray | None]:
        return list(self.venv.render() or ())
