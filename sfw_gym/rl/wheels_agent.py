"""``wheels-ppo``: PPO trained from scratch on ``SfW-Explore-v0``'s own wheel commands.

The policy (:class:`sfw_gym.rl.wheels_policy.WheelsPolicy`) reads the env's observation and
names a (linear, angular) command: no planner, no waypoints, no teacher. A policy trained with
:class:`~sfw_gym.envs.action_repeat.ActionRepeat` (its run's ``config.yml`` says so) decides
every ``repeat`` steps and holds its command in between, as in training.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sfw_gym.agents.base import RobotView
from sfw_gym.core.data import DEFAULT_WHEELS_MODEL_DIR
from sfw_gym.core.errors import ConfigError
from sfw_gym.rl.training import native_action_repeat, wrapper_specs
from sfw_gym.rl.waypoint_agent import WaypointPPOAgent, WaypointPPOSettings


@dataclass(frozen=True)
class WheelsPPOSettings(WaypointPPOSettings):
    """:class:`WheelsPPOAgent`'s parameters: by default the shipped policy."""

    path: str = str(DEFAULT_WHEELS_MODEL_DIR)


class WheelsPPOAgent(WaypointPPOAgent):
    """Acts with a PPO policy on the env's continuous actions (by default the shipped one).

    Its parameters are :class:`WheelsPPOSettings`' fields, given as keyword arguments: ``path``
    (a ``sfw-gym train ppo`` output folder or its ``.zip``), ``deterministic`` (the Gaussian's
    mean, the default, so that an episode is a function of the env seed alone; else a draw from
    it with the agent's seeded generator), ``device``, ``max_steps``.
    """

    name = "wheels-ppo"
    # declared on the class, before any model is loaded (the registry's readers see it)
    action_types = ("continuous",)
    settings_class = WheelsPPOSettings
    settings: WheelsPPOSettings

    def _check_policy_kind(self, folder: Path, config: dict[str, Any]) -> None:
        if self.waypoints is not None:
            raise ConfigError(
                f"WheelsPPOAgent: {folder} holds a waypoint policy; use the waypoint-ppo agent"
            )
        wrappers = wrapper_specs(config.get("hyperparameters", {}).get("env_wrapper"))
        repeat = native_action_repeat(wrappers)
        if repeat is None:
            raise ConfigError(
                f"WheelsPPOAgent: {folder} was trained through {[w for w, _ in wrappers]}, "
                "which this agent cannot replay"
            )
        self.action_repeat = repeat

    def _on_reset(self, view: RobotView) -> None:
        super()._on_reset(view)
        self._held, self._command = 0, (0.0, 0.0)
        self.n_decisions = 0  # the policy's commands this episode

    def _act(self, view: RobotView, obs: Any) -> tuple[float, float]:
        if self._held == 0:  # a decision every action_repeat steps, as in training
            self._command = super()._act(view, obs)
            self._held = self.action_repeat
            self.n_decisions += 1
        self._held -= 1
        return self._command
