"""Hold each action for several env steps: one decision per ``repeat`` steps, the rewards summed.

The standard frame skip of Atari agents: a policy on the wheels decides every 0.8 s instead of
every 0.2 s, sees four times as far with the same discount and learns from a quarter of the
decisions. ``sfw-gym train`` applies the same repeat on the native vector env
(:class:`sfw_gym.rl.vec_env.SB3VecEnv`'s ``action_repeat``) when this is the YAML's only
``env_wrapper``; rl-baselines3-zoo applies this wrapper per env.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym

from sfw_gym.core.errors import ConfigError

#: The repeat of the shipped recipe (a decision every 0.8 s at the env's 0.2 s a step).
DEFAULT_REPEAT = 4


class ActionRepeat(gym.Wrapper):
    """Each action held for ``repeat`` steps of ``env`` (fewer when the episode ends first); the
    reward is their sum, the observation and info the last step's."""

    def __init__(self, env: gym.Env, repeat: int = DEFAULT_REPEAT) -> None:
        if isinstance(repeat, bool) or not isinstance(repeat, int) or repeat < 1:
            raise ConfigError(f"ActionRepeat: repeat must be an integer ≥ 1, got {repeat!r}")
        super().__init__(env)
        self.repeat = repeat

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        total = 0.0
        for _ in range(self.repeat):
            obs, reward, terminated, truncated, info = self.env.step(action)
            total += float(reward)
            if terminated or truncated:
                break
        return obs, total, terminated, truncated, info
