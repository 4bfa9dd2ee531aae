"""Episodes on a vector env in this process (``sfw-gym evaluate --vector-envs N``).

``gym.make_vec(id, num_envs=N)`` gives the native vector env (:class:`~sfw_gym.envs.vector.
SfWVectorEnv`; every SfW id registers it, an id without one is refused). Its explore sub-envs
step together in one compiled batch, the other env classes one by one. Each sub-env runs one episode
after another: when one ends, its record is taken from the sub-env, and the sub-env is reset alone
(``reset_mask``) with the next episode's seed and plan. That reset clears its pending autoreset.
One agent per episode acts in this process. It is reset with its sub-env as in
:func:`~sfw_gym.evaluation.rollout.run_episode`, so it holds only a
:class:`~sfw_gym.agents.base.RobotViewHandle` (``robot_view()``, never the ground truth). The
records are built by :class:`~sfw_gym.evaluation.rollout.EpisodeRecord`, so they are the
sequential run's records.
"""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Generator, Sequence
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


def sub_env_row(batched: dict[str, Any], i: int) -> dict[str, Any]:
    """Sub-env ``i``'s own dict out of a vector env's batched ``obs`` or ``info``: each key
    whose ``_key`` mask marks it (an info; nested dicts likewise), or every key (an obs)."""
    row = {}
    for key, value in batched.items():
        mask = batched.get(f"_{key}")
        if mask is None and key.startswith("_") and key[1:] in batched:
            continue  # a mask
        if mask is None or mask[i]:
            row[key] = sub_env_row(value, i) if isinstance(value, dict) else value[i]
    return row


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
            mask = np.zeros(n, np.bool_)
            mask[i] = True
            seeds: list[int | None] = [None] * n
            seeds[i] = spec.seed
            options: dict[str, Any] = {"reset_mask": mask}
            if spec.floorplan:
                options["floorplan"] = spec.floorplan
            obs, infos = vec.reset(seed=seeds, options=options)
            episode = EpisodeRecord(spec, sub_env_row(infos, i), begin)
            agent = make_agent(spec.agent, **spec.agent_params)
            agent.reset(vec.envs[i], seed=spec.agent_reset_seed)
            slots[i] = _Slot(index, agent, episode, sub_env_row(obs, i))

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
                info = sub_env_row(infos, i)
                slot.obs = sub_env_row(obs, i)
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


def _standing_action(space: gym.Space) -> Any:
    """An action that keeps an idle sub-env's robot still (continuous) or turning on the spot
    (discrete), so that it meets no walls."""
    if isinstance(space, gym.spaces.Discrete):
        from sfw_gym.core.constants import DISCRETE_ACTION_NAMES

        return space.start + DISCRETE_ACTION_NAMES.index("turn_left")
    return np.zeros(space.shape, space.dtype)
