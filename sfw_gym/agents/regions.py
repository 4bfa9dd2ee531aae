"""Region decisions on the explore env: the hierarchical explorer behind the agents' interface.

:class:`RegionAgent` acts on ``SfW-Explore-v0`` (and every explore id) exactly as
``SfW-ExploreRegions-v0`` does: every ``decision_steps`` steps it builds the same candidate menu,
picks a region (:meth:`RegionAgent.choose`) and lets the same
:class:`~sfw_gym.navigation.regions.RegionSteering` drive towards it. Its own choice is the
teacher's (by default the expected bits per metre on the menu): ``region-teacher``, the level a
learned region policy (:class:`sfw_gym.rl.agent.RegionsPPOAgent`) starts from.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from sfw_gym.agents.base import Agent, AgentSettings, RobotView
from sfw_gym.core.config import setting
from sfw_gym.envs.goals import action_masks, menu_observation
from sfw_gym.envs.regions import RegionsConfig, region_anchor
from sfw_gym.navigation.candidates import GoalFinder
from sfw_gym.navigation.goal_driver import GoalDriver
from sfw_gym.navigation.menu import TEACHERS, CandidateGoals
from sfw_gym.navigation.regions import RegionSteering


@dataclass(frozen=True)
class RegionAgentSettings(AgentSettings):
    """The parameters of :class:`RegionAgent`.

    Attributes:
        regions: :class:`~sfw_gym.envs.regions.RegionsConfig` fields (dict), as the env's.
        teacher: Whose choice on the menu (:data:`~sfw_gym.navigation.menu.TEACHERS`):
            ``greedy`` (expected bits per metre, the tuned greedy agent's offset: the region
            teacher, level with frontier) or ``explore_lite`` (the frontier agent's utility,
            which lost coverage on region actions).
    """

    regions: dict[str, Any] | None = None
    teacher: str = setting("greedy", choices=sorted(TEACHERS))

    def validate(self) -> None:
        RegionsConfig.from_dict(self.regions, "regions")


class RegionAgent(Agent):
    """Region decisions every ``decision_steps`` steps, steered as ``SfW-ExploreRegions-v0``.

    Parameters: :class:`RegionAgentSettings` (keyword arguments, checked).
    """

    name = "region-teacher"

    settings_class = RegionAgentSettings
    settings: RegionAgentSettings

    def __init__(self, **params: Any) -> None:
        super().__init__(**params)
        self.config = RegionsConfig.from_dict(self.settings.regions, "regions")

    def _on_reset(self, view: RobotView) -> None:
        cfg = self.config
        self.finder = GoalFinder()
        self.finder.reset(view)
        driver = GoalDriver(self.finder, cfg.max_steps_per_goal)
        driver.reset()
        self.steering = RegionSteering(self.finder, driver, cfg.anchor_cost_per_m)
        self.steering.reset()
        self.n_decisions = 0

    def _act(self, view: RobotView, obs: Any) -> tuple[float, float]:
        command = self.steering.command(view, self.steps)
        if command is None:  # the decision's steps are spent (or the first step): choose
            self.finder.set_step(self.steps)
            k = self.config.max_candidates
            menu, extra = menu_observation(self.finder, view, k)
            choice = self.choose(view, obs, menu, extra)
            anchor = region_anchor(menu, choice)
            if anchor is not None:
                self._log_decision(menu, choice)
            self.steering.start(anchor, self.config.decision_steps)
            self.n_decisions += 1
            command = self.steering.command(view, self.steps)
        assert command is not None
        return command

    def choose(
        self, view: RobotView, obs: Any, menu: CandidateGoals, extra: dict[str, np.ndarray]
    ) -> int:
        """The region: a candidate index (the ``teacher``'s choice on the menu, the first
        allowed candidate when it has none). ``extra``: the menu's observation entries
        (``candidates``, ``candidate_mask``)."""
        choice = TEACHERS[self.settings.teacher](menu)
        if choice is None:
            return int(np.argmax(action_masks(menu, self.config.max_candidates)))
        return choice
