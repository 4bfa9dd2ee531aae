"""Episodes on a ``gymnasium.vector`` env (``sfw-gym evaluate --vector-envs N``): N sub-envs in
worker processes, each taking the next episode when its own ends and reset with that episode's
own seed and plan (autoreset disabled, ``reset_mask``); the agents act in this process on what the
sub-envs return (``info["robot_view"]``, :class:`~sfw_gym.envs.RobotViewInInfo`). The records are
the ones the single-env rollout gives (:class:`~sfw_gym.evaluation.rollout.EpisodeRecord`)."""

from __future__ import annotations

import time
from collections.abc import Generator, Sequence
from dataclasses import dataclass
from typing import Any, cast

import gymnasium as gym
import numpy as np
from gymnasium.vector import AsyncVectorEnv

from sfw_gym.core.errors import ConfigError
from sfw_gym.evaluation.rollout import EpisodeRecord, EpisodeSpec


class _Unbatched:
    """A sub-env's observation and info as it returned them (an opaque object, so that the
    vector env hands it over as it is instead of batching its fields)."""

    def __init__(self, obs: Any, info: dict[str, Any]) -> None:
        self.obs, self.info = obs, info


class StepInInfo(gym.Wrapper):
    """Puts each reset's and step's ``(obs, info)`` into ``info["unbatched"]``: what the
    sub-env returned, field for field (a vector env batches ``obs`` and ``info`` otherwise)."""

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        obs, info = self.env.reset(seed=seed, options=options)
        return obs, {"unbatched": _Unbatched(obs, info)}

    def step(self, action: Any) -> tuple[Any, Any, bool, bool, dict[str, Any]]:
        obs, reward, terminated, truncated, info = self.env.step(action)
        return obs, reward, terminated, truncated, {"unbatched": _Unbatched(obs, info)}


@dataclass
class _Slot:
    """The episode a sub-env is running."""

    index: int
    spec: EpisodeSpec
    agent: Any
    episode: EpisodeRecord
    obs: Any
    info: dict[str, Any]


def make_vector_env(spec: EpisodeSpec, num_envs: int) -> AsyncVectorEnv:
    """``num_envs`` sub-envs of ``spec``'s env id and kwargs, each in a ``spawn``-ed process
    (forking a process that has run numba's OpenMP kernels is unsafe), wrapped in
    :class:`~sfw_gym.envs.RobotViewInInfo` and :class:`StepInInfo`, autoreset disabled."""
    from gymnasium.vector import AutoresetMode

    from sfw_gym.envs import RobotViewInInfo

    vec = gym.make_vec(
        spec.env_id,
        num_envs=num_envs,
        vectorization_mode="async",
        vector_kwargs={"autoreset_mode": AutoresetMode.DISABLED, "context": "spawn"},
        wrappers=[RobotViewInInfo, StepInInfo],
        **spec.env_kwargs,
    )
    return cast(AsyncVectorEnv, vec)


def run_vector(
    specs: Sequence[EpisodeSpec], num_envs: int
) -> Generator[tuple[int, dict[str, Any]], None, None]:
    """Run ``specs`` (one env id and kwargs, no GIFs) on a vector env of ``num_envs`` sub-envs;
    yields ``(index in specs, record)`` as each episode ends."""
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
    queue = list(enumerate(specs))
    vec = make_vector_env(first, n)
    try:
        vec.reset()  # every sub-env once, before the per-episode resets below
        idle = vec.single_action_space.sample()  # what a sub-env with no episode left is sent
        slots: list[_Slot | None] = [None] * n

        def reset(i: int, seed: int | None, floorplan: str | None) -> tuple[Any, dict[str, Any]]:
            """Reset sub-env ``i`` alone with its episode's seed and plan."""
            mask = np.zeros(n, np.bool_)
            mask[i] = True
            seeds: list[int | None] = [None] * n
            seeds[i] = seed
            options: dict[str, Any] = {"reset_mask": mask}
            if floorplan:
                options["floorplan"] = floorplan
            _, infos = vec.reset(seed=seeds, options=options)
            got = infos["unbatched"][i]
            return got.obs, got.info

        def start(i: int) -> None:
            """Sub-env ``i`` takes the next episode, or idles on a throwaway one."""
            if not queue:
                slots[i] = None
                reset(i, None, None)  # the vector env steps every sub-env
                return
            index, spec = queue.pop(0)
            begin = time.perf_counter()
            obs, info = reset(i, spec.seed, spec.floorplan)
            agent = make_agent(spec.agent, **spec.agent_params)
            agent.reset(info=info, seed=spec.agent_reset_seed)
            slots[i] = _Slot(index, spec, agent, EpisodeRecord(spec, info, begin), obs, info)

        for i in range(n):
            start(i)
        while any(slots):
            actions = [idle if s is None else s.agent.act(s.obs, s.info) for s in slots]
            _, _, terminated, truncated, infos = vec.step(np.stack(actions))
            for i, slot in enumerate(slots):
                got = infos["unbatched"][i]
                done = bool(terminated[i] or truncated[i])
                if slot is None:
                    if done:
                        start(i)
                    continue
                slot.obs, slot.info = got.obs, got.info
                slot.episode.step(got.info, done)
                if done:
                    truth = vec.call("ground_truth")[i]
                    belief = got.info["robot_view"].belief_u8
                    yield (
                        slot.index,
                        slot.episode.finish(
                            got.info, bool(terminated[i]), slot.agent, truth, belief
                        ),
                    )
                    start(i)
    finally:
        vec.close()
