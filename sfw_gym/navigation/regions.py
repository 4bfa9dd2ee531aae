"""Steering inside a chosen region: the low level of the hierarchical explorer.

A decision of ``SfW-ExploreRegions-v0`` (and of the learned agent trained on it) picks a region
— the target cell of one candidate of the menu, its *anchor* — and then :class:`RegionSteering`
drives for a fixed number of steps with the classical rule: explore_lite's choice among the
frontier clusters (:func:`~sfw_gym.navigation.menu.explore_lite_choice`), each cluster's
utility lowered by ``anchor_cost_per_m`` per metre between it and the anchor, each goal driven
by :class:`~sfw_gym.navigation.goal_driver.GoalDriver`. The high level says where to explore;
the low level keeps collecting the information that lies along the way (on an RSSI map it comes
from the router rays the robot crosses near itself, not from a goal's endpoint), as Active
Neural SLAM splits a global policy from its local one.
"""

from __future__ import annotations

import numpy as np

from sfw_gym.navigation.candidates import GoalFinder
from sfw_gym.navigation.goal_driver import TURN, GoalDriver, resolved
from sfw_gym.navigation.menu import POTENTIAL_SCALE, explore_lite_utilities, proven_on_bounded_paths
from sfw_gym.navigation.planning import SEARCH_RADIUS_M, cost_field
from sfw_gym.navigation.view import RobotView

#: The micro menu: frontier clusters and the features explore_lite's utility reads.
_MICRO = {
    "sources": ("frontier",),
    "features": ("path_cost_m", "heading_change_rad", "cluster_size_m"),
}


class RegionSteering:
    """One region decision at a time: :meth:`start`, then :meth:`command` before every step
    until it returns None (after ``steps`` commands).

    Args:
        finder: The episode's :class:`GoalFinder` (shared with the high level's menu).
        driver: The episode's :class:`GoalDriver` over ``finder``.
        anchor_cost_per_m: Utility (metres of frontier) lost per metre between a cluster's
            target and the anchor; 0 is the classical rule alone.
    """

    def __init__(self, finder: GoalFinder, driver: GoalDriver, anchor_cost_per_m: float) -> None:
        self.finder, self.driver = finder, driver
        self.anchor_cost_per_m = anchor_cost_per_m
        self.anchor_rc: tuple[int, int] | None = None
        self.remaining = 0
        self.micro_decisions = 0
        self.full_searches = 0  # micro decisions whose bounded search could not prove the choice
        self._driving = False  # a goal of this decision is being driven

    def reset(self) -> None:
        """A new episode (after the finder's and the driver's resets)."""
        self.anchor_rc, self.remaining, self.micro_decisions = None, 0, 0
        self.full_searches = 0
        self._driving = False

    def start(self, anchor_rc: tuple[int, int] | None, steps: int) -> None:
        """Steer towards ``anchor_rc`` (None: no region, the classical rule) for ``steps``."""
        self.anchor_rc, self.remaining = anchor_rc, steps
        self._driving = False  # the first step chooses a goal with the new anchor

    def command(self, view: RobotView, step: int) -> tuple[float, float] | None:
        """The command for this step (``step``: the episode's step count), or None: the
        decision's steps are spent."""
        if self.remaining <= 0:
            return None
        if self.anchor_rc is not None and resolved(view, self.anchor_rc):
            self.anchor_rc = None  # the region is explored: the classical rule alone from here
        command = self.driver.command(view) if self._driving else None
        if command is None:
            self.finder.set_step(step)
            self._choose(view)
            command = self.driver.command(view)
        self.remaining -= 1
        return TURN if command is None else command

    def _choose(self, view: RobotView) -> None:
        """Start the driver on the micro menu's best goal near the anchor (when no frontier
        cluster is reachable: the cheapest valid goal of the full menu — hidden rooms and
        information-gain points —, else one step turning)."""
        res = view.grid.resolution_m
        costs = self.finder.costs(view)
        for bound in (SEARCH_RADIUS_M, np.inf):  # a bounded search first, kept when proven
            paths = cost_field(costs, view.cell, res, max_cost_m=bound)
            # explore_lite's utility minus anchor_cost_per_m per metre from the anchor: the
            # same per path metre (÷ POTENTIAL_SCALE) where a cluster's cheapest cell is chosen
            menu = self.finder.find(
                view,
                paths,
                anchor_rc=self.anchor_rc,
                anchor_cost_per_m=self.anchor_cost_per_m / POTENTIAL_SCALE,
                **_MICRO,  # type: ignore[arg-type]
            )
            utility = explore_lite_utilities(menu, self.anchor_rc, self.anchor_cost_per_m, res)
            if proven_on_bounded_paths(menu, utility):
                break
            self.full_searches += 1
        choice = int(np.argmax(utility)) if np.isfinite(utility).any() else None
        if choice is None:
            menu = self.finder.find(view, paths, max_candidates=16)
            cost = np.where(menu.valid, menu.feature("path_cost_m"), np.inf)
            choice = int(np.argmin(cost)) if len(menu) else 0
        self.driver.start(view, menu, choice)
        self._driving = True
        self.micro_decisions += 1
