"""Episodes on a vector env in this process (``sfw-gym evaluate --vector-envs N``).

The env is ``gym.make_vec(id, num_envs=N)``'s native vector env
(:class:`~sfw_gym.envs.vector.SfWVectorEnv`; every SfW id registers it, an id without one is
refused). Its explore sub-envs step together in one compiled batch, other env classes one by
one. Each sub-env runs one episode after another. When one ends, its record is taken from the
sub-env, which is then reset alone (``reset_mask``, clearing its pending autoreset) with the
next episode's seed and plan. One agent per episode acts in this process. It is reset with its
sub-env as :func:`~sfw_gym.evaluation.rollout.run_episode` resets it, so it holds only a
:class:`~sfw_gym.agents.base.RobotViewHandle` (``robot_view()``, never the ground truth).
:class:`~sfw_gym.evaluation.rollout.EpisodeRecord` builds the records, so they are the
sequential run's.
"""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Generator, Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, cast

import gymnasium as gym
import numpy as np

from sfw_gym.core.errors import ConfigError
from sfw_gym.envs.explore import unwrap_sfw
from sfw_gym.evaluation.rollout import EpisodeRecord, EpisodeSpec

if TYPE_CHECKING:
    from sfw_gym.envs.vector import SfWVectorEnv


@dataclass
class _Slot:
    """The episode a sub-env is running."""

    index: int
    agent: Any
    episode: EpisodeRecord
    obs: Any


class SubEnvInfo(Mapping[str, Any]):
    """Sub-env ``i``'s info, read out of a vector env's batched info key by key when asked (a
    record reads few of a step's keys): each key whose ``_key`` mask marks sub-env ``i``,
    nested dicts likewise."""

    __slots__ = ("_batched", "_i")

    def __init__(self, batched: dict[str, Any], i: int) -> None:
        self._batched, self._i = batched, i

    def __getitem__(self, key: str) -> Any:
        mask = self._batched.get(f"_{key}")
        if mask is None or not mask[self._i]:
            raise KeyError(key)
        value = self._batched[key]
        return SubEnvInfo(value, self._i) if isinstance(value, dict) else value[self._i]

    def __iter__(self) -> Iterator[str]:
        batched, i = self._batched, self._i
        return (k for k in batched if f"_{k}" in batched and batched[f"_{k}"][i])

    def __len__(self) -> int:
        return sum(1 for _ in self)


def check_native_vector_env(env_id: str) -> None:
    """Raise a ConfigError unless ``env_id`` has a native vector env (a ``vector_entry_point``;
    an unknown id raises gymnasium's NameNotFound)."""
    if gym.spec(env_id).vector_entry_point is None:
        raise ConfigError(
            f"--vector-envs: {env_id} has no native vector env (every SfW id has one); "
            "run it with --workers"
        )


def run_vector(
    specs: Sequence[EpisodeSpec], num_envs: int
) -> Generator[tuple[int, dict[str, Any]], None, None]:
    """Run ``specs`` (one env id and kwargs, no GIFs) on a vector env of ``num_envs``
    sub-envs in this process; yields ``(index in specs, record)`` as each episode ends."""
    from sfw_gym.agents import make_agent

    if not specs:
        return
    first = specs[0]
    for spec in specs:
        if (spec.env_id, spec.env_kwargs) != (first.env_id, first.env_kwargs):
            raise ConfigError("--vector-envs: every episode must use the same env and env kwargs")
        if spec.gif_path:
            raise ConfigError("--vector-envs: GIFs are not recorded on a vector env (no --gif)")
    n = min(num_envs, len(specs))
    queue = deque(enumerate(specs))
    check_native_vector_env(first.env_id)
    vec = cast(
        "SfWVectorEnv",
        gym.make_vec(
            first.env_id, num_envs=n, vectorization_mode="vector_entry_point", **first.env_kwargs
        ),
    )
    try:
        idle = _standing_action(vec.single_action_space)  # for a sub-env with no episode left
        slots: list[_Slot | None] = [None] * n

        def start(i: int) -> None:
            """Sub-env ``i`` takes the next episode (reset with its seed and plan), or idles."""
            slots[i] = None
            if not queue:
                return
            index, spec = queue.popleft()
            begin = time.perf_counter()
            obs, infos = reset_sub_env(vec, i, spec.seed, spec.reset_options)
            episode = EpisodeRecord(spec, SubEnvInfo(infos, i), begin)
            agent = make_agent(spec.agent, **spec.agent_params)
            agent.reset(vec.envs[i], seed=spec.agent_reset_seed)
            slots[i] = _Slot(index, agent, episode, {k: v[i] for k, v in obs.items()})

        for i in range(n):
            start(i)
        while any(slots):
            vec.envs  # noqa: B018 (writes the batched state back into the sub-envs: their views)
            actions = [idle if s is None else s.agent.act(s.obs) for s in slots]
            obs, _, terminated, truncated, infos = vec.step(np.stack(actions))
            for i, slot in enumerate(slots):
                if slot is None:
                    continue
                done = bool(terminated[i] or truncated[i])
                info = SubEnvInfo(infos, i)
                slot.obs = {k: v[i] for k, v in obs.items()}
                slot.episode.step(info, done)
                if done:
                    sfw = unwrap_sfw(vec.envs[i])
                    truth, belief = sfw.ground_truth(), sfw.robot_view().belief_u8
                    record = slot.episode.finish(
                        info, bool(terminated[i]), slot.agent, truth, belief
                    )
                    yield slot.index, record
                    start(i)
    finally:
        vec.close()


def reset_sub_env(
    vec: Any, i: int, seed: int, options: dict[str, Any] | None = None
) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
    """Reset sub-env ``i`` of a native vector env alone (``reset_mask``, clearing its pending
    autoreset) with ``seed`` and its ``options`` (a plan file, routers: :attr:`EpisodeSpec.
    reset_options`); the others go on as they were."""
    n = vec.num_envs
    mask = np.zeros(n, np.bool_)
    mask[i] = True
    seeds: list[int | None] = [None] * n
    seeds[i] = seed
    return vec.reset(seed=seeds, options={**(options or {}), "reset_mask": mask})


def _standing_action(space: gym.Space) -> Any:
    """An action that keeps an idle sub-env's robot still (continuous) or turning on the spot
    (discrete), so that it meets no walls."""
    if isinstance(space, gym.spaces.Discrete):
        from sfw_gym.core.constants import DISCRETE_ACTION_NAMES

        return space.start + DISCRETE_ACTION_NAMES.index("turn_left")
    return np.zeros(space.shape, space.dtype)
