"""Carry the robot's view in ``info``, so that classical agents can act on what an env returns
(behind a ``gymnasium.vector`` env, in another process, under RLlib) rather than on the env."""

from __future__ import annotations

from typing import Any

import gymnasium as gym

from sfw_gym.core.errors import ConfigError


class RobotViewInInfo(gym.Wrapper):
    """Adds ``info["robot_view"]``: the :class:`~sfw_gym.navigation.view.RobotView` after each
    ``reset`` and ``step`` (what ``env.unwrapped.robot_view()`` returns; never the truth).

    Agents read it with ``agent.reset(info=info)`` and ``agent.act(obs, info)``::

        envs = gym.make_vec(
            "SfW-Explore-v0", num_envs=2, vectorization_mode="sync", wrappers=[RobotViewInInfo]
        )

    (Gymnasium applies ``wrappers`` to its ``sync`` and ``async`` vector envs only, not to a
    ``vector_entry_point``.) In the same process the view's arrays are read-only views of the
    env's state, valid until its next ``step`` (copy what you keep); across processes they
    arrive as copies.

    Raises:
        ConfigError: If the env has no ``robot_view()`` (not an SfW env).
    """

    def __init__(self, env: gym.Env) -> None:
        super().__init__(env)
        if not callable(getattr(env.unwrapped, "robot_view", None)):
            got = type(env.unwrapped).__name__
            raise ConfigError(f"RobotViewInInfo needs an SfW env with robot_view(), got {got}")

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        obs, info = self.env.reset(seed=seed, options=options)
        return obs, {**info, "robot_view": self.env.unwrapped.robot_view()}  # type: ignore[attr-defined]

    def step(self, action: Any) -> tuple[Any, Any, bool, bool, dict[str, Any]]:
        obs, reward, terminated, truncated, info = self.env.step(action)
        view = self.env.unwrapped.robot_view()  # type: ignore[attr-defined]
        return obs, reward, terminated, truncated, {**info, "robot_view": view}
