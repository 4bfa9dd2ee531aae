"""``wheels-ppo``: PPO trained from scratch on ``SfW-Explore-v0``'s own wheel commands.

The policy (:class:`sfw_gym.rl.wheels_policy.WheelsPolicy`) reads the env's observation and
names a (linear, angular) command every step: no planner, no waypoints, no teacher. The agent
feeds it the observation the env returns, as in training.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from sfw_gym.core.data import DEFAULT_WHEELS_MODEL_DIR
from sfw_gym.core.errors import ConfigError
from sfw_gym.rl.agent import LearnedAgentSettings
from sfw_gym.rl.waypoint_agent import WaypointPPOAgent


@dataclass(frozen=True)
class WheelsPPOSettings(LearnedAgentSettings):
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
    action_types = ("continuous",)
    settings_class = WheelsPPOSettings
    settings: WheelsPPOSettings

    def _check_policy_kind(self, folder: Path) -> None:
        if self.waypoints is not None:
            raise ConfigError(
                f"WheelsPPOAgent: {folder} holds a waypoint policy; use the waypoint-ppo agent"
            )
