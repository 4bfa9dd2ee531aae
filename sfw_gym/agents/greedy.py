"""Greedy information gain per metre: the reference 'next-best-view' agent for the RSSI mapper."""

from __future__ import annotations

from typing import Any

import numpy as np

from sfw_gym.agents.base import RobotView
from sfw_gym.agents.frontier import FrontierAgent, Goal
from sfw_gym.core.config import check
from sfw_gym.navigation.candidates import (
    CandidateSettings,
    bits_per_metre,
)
from sfw_gym.navigation.planning import CostField


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

    Args:
        max_candidates: Candidates scored per replan (an even subsample of frontier cells).
        distance_offset_m: Added to the path distance (keeps near goals from dominating).
        zones_every_steps: Re-fit the router model this often.
        **frontier_params: Parameters of :class:`FrontierAgent`.

    Attributes:
        candidates: The latest choice's menu: ``(cell, score)`` per candidate; the goal is the
            one of highest score.
    """

    name = "greedy"
    _bounded_search = False

    def __init__(
        self,
        max_candidates: int = 300,
        distance_offset_m: float = 1.0,
        zones_every_steps: int = 25,
        **frontier_params: Any,
    ) -> None:
        super().__init__(**frontier_params)
        self.max_candidates = check("max_candidates", max_candidates, integer=True, ge=1)
        self.distance_offset_m = check("distance_offset_m", distance_offset_m, ge=0.01)
        self.zones_every_steps = check("zones_every_steps", zones_every_steps, integer=True, ge=1)

    def _candidate_settings(self) -> CandidateSettings:
        return CandidateSettings(
            **{
                **super()._candidate_settings().to_dict(),
                "info_gain_samples": self.max_candidates,
                "zones_every_steps": self.zones_every_steps,
            }
        )

    def expected_gain(self, view: RobotView, cells: np.ndarray) -> np.ndarray:
        """Bits the mapper would gain with the robot at each of ``cells`` (N, 2)."""
        return self.finder.expected_gain(view, cells)

    def _choose_goal(self, view: RobotView, paths: CostField) -> Goal | None:
        self.candidates = []
        if not self.finder.frontier(view).any():
            self._stop("no_frontiers")
            return None
        menu = self.finder.find(
            view, paths, sources=("info_gain",), features=("path_cost_m", "expected_gain_bits")
        )
        self.finder.mark_unreachable(menu.walled_off_rc, self.steps + self.unreachable_ttl_steps)
        if len(menu) == 0:
            self._stop("all_blacklisted")
            return None
        score = bits_per_metre(menu, self.distance_offset_m)
        self.candidates = [
            ((int(r), int(c)), s)
            for (r, c), s in zip(menu.target_rc.tolist(), score.tolist(), strict=True)
        ]
        i = int(np.argmax(score))
        self._log_decision(menu, i)
        self._resume()
        target = (int(menu.target_rc[i, 0]), int(menu.target_rc[i, 1]))
        return Goal((int(menu.goal_rc[i, 0]), int(menu.goal_rc[i, 1])), target, "frontier")
