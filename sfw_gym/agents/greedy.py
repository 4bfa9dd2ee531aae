"""Greedy information gain per metre: the reference 'next-best-view' agent for the RSSI mapper."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sfw_gym.agents.base import RobotView
from sfw_gym.agents.frontier import FrontierAgent, FrontierSettings, Goal
from sfw_gym.core.config import setting
from sfw_gym.navigation.candidates import CandidateSettings
from sfw_gym.navigation.menu import CandidateGoals, bits_per_metre
from sfw_gym.navigation.planning import CostField


@dataclass(frozen=True)
class GreedySettings(FrontierSettings):
    """The parameters of :class:`GreedyInfoGainAgent`.

    Attributes:
        max_candidates: Candidates scored per replan (an even subsample of frontier cells).
        distance_offset_m: Added to the path distance (keeps near goals from dominating).
        zones_every_steps: Re-fit the router model this often.
    """

    max_candidates: int = setting(300, integer=True, ge=1)
    distance_offset_m: float = setting(1.0, ge=0.01)
    zones_every_steps: int = setting(25, integer=True, ge=1)


class GreedyInfoGainAgent(FrontierAgent):
    """Drive to the candidate goal with the most expected information gain per metre of path.

    Candidates are the ``info_gain`` points of the shared menu
    (:class:`~sfw_gym.navigation.candidates.GoalFinder`): frontier cells, subsampled. A
    candidate's expected gain is the entropy (bits) of the unknown cells the mapper would update
    from there: those on the ray from the router predicted to be the strongest at the candidate
    (log-distance model with the robot's own RSSI residuals) to the candidate, plus the unknown
    cells in the robot's footprint there. The score is that gain divided by the path cost plus
    ``distance_offset_m``. Motion, bumps, blacklisting and the
    fallback sweep are :class:`FrontierAgent`'s.

    Parameters: :class:`GreedySettings` (keyword arguments, checked).

    Attributes:
        candidates: The latest choice's menu: ``(cell, score)`` per candidate; the goal is the
            one of highest score.
    """

    name = "greedy"
    _bounded_search = False

    settings_class = GreedySettings
    settings: GreedySettings

    def _candidate_settings(self) -> CandidateSettings:
        return CandidateSettings(
            **{
                **super()._candidate_settings().to_dict(),
                "info_gain_samples": self.settings.max_candidates,
                "zones_every_steps": self.settings.zones_every_steps,
            }
        )

    def expected_gain(self, view: RobotView, cells: np.ndarray) -> np.ndarray:
        """Bits the mapper would gain with the robot at each of ``cells`` (N, 2)."""
        return self.finder.expected_gain(view, cells)

    def _info_gain_menu(
        self, view: RobotView, paths: CostField, features: tuple[str, ...]
    ) -> CandidateGoals | None:
        """The menu of frontier cells (subsampled) with ``features``, its walled-off cells
        marked unreachable; None (and the stop reason) when no frontier is left."""
        self.candidates = []
        if not self.finder.frontier(view).any():
            self._stop("no_frontiers")
            return None
        menu = self.finder.find(view, paths, sources=("info_gain",), features=features)
        self.finder.mark_unreachable(
            menu.walled_off_rc, self.steps + self.settings.unreachable_ttl_steps
        )
        return menu

    def _choose_goal(self, view: RobotView, paths: CostField) -> Goal | None:
        menu = self._info_gain_menu(view, paths, ("path_cost_m", "expected_gain_bits"))
        if menu is None:
            return None
        if len(menu) == 0:
            self._stop("all_blacklisted")
            return None
        score = bits_per_metre(menu, self.settings.distance_offset_m)
        self.candidates = list(
            zip(map(tuple, menu.target_rc.tolist()), score.tolist(), strict=True)
        )
        i = int(np.argmax(score))
        self._log_decision(menu, i)
        self._resume()
        target = (int(menu.target_rc[i, 0]), int(menu.target_rc[i, 1]))
        return Goal((int(menu.goal_rc[i, 0]), int(menu.goal_rc[i, 1])), target, "frontier")
