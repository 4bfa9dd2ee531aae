"""A random-walk reference agent."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from sfw_gym.agents.base import Agent, AgentSettings, RobotView
from sfw_gym.core.config import setting
from sfw_gym.core.constants import DISCRETE_ACTIONS

#: (linear, angular) of the discrete actions 0 forward, 1 turn left, 2 turn right.


@dataclass(frozen=True)
class RandomSettings(AgentSettings):
    """The parameters of :class:`RandomAgent`.

    Attributes:
        hold_steps: Steps each drawn action is repeated.
    """

    hold_steps: int = setting(5, integer=True, ge=1)


class RandomAgent(Agent):
    """Uniformly random actions, each held for ``hold_steps`` steps (a new one after a bump).

    Continuous actions are drawn from ``U([-1, 1]²)``, discrete ones uniformly from the three
    actions. With ``hold_steps=1`` this is the usual i.i.d. random policy; holding makes a
    correlated random walk that gets somewhere, a fairer reference.

    Parameters: :class:`RandomSettings` (keyword arguments, checked).
    """

    name = "random"

    settings_class = RandomSettings
    settings: RandomSettings

    def _on_reset(self, view: RobotView) -> None:
        self._held = 0
        self._command = (0.0, 0.0)

    def _act(self, view: RobotView, obs: Any) -> tuple[float, float]:
        if self._held <= 0 or view.bumped:
            if self.action_type == "discrete":
                self._command = DISCRETE_ACTIONS[int(self.rng.integers(len(DISCRETE_ACTIONS)))]
            else:
                lin, ang = self.rng.uniform(-1.0, 1.0, 2)
                self._command = (float(lin), float(ang))
            self._held = self.settings.hold_steps
        self._held -= 1
        return self._command
