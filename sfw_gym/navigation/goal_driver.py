"""Driving to one candidate goal at a time: the decision of a candidate-goal explorer.

:class:`GoalDriver` turns "go to candidate i of this menu" into one ``(linear, angular)`` command
per step, as the frontier agent drives to its goals: pure pursuit along the candidate's path with
the finder's goal tolerance; the decision ends when the target cell is resolved, at a bump (a
wall ahead is remembered and backed off; every third slide along a wall since the last back-off
backs off too), when the goal is reached (a target still unknown then is blacklisted a while),
or after ``max_steps``. Shared by ``SfW-ExploreGoals-v0`` (one env
step per command) and the learned agent that drives ``SfW-Explore-v0`` the same way.
"""

from __future__ import annotations

import numpy as np

from sfw_gym.core.constants import U8_FREE_MIN, U8_WALL_MAX
from sfw_gym.navigation.candidates import GoalFinder
from sfw_gym.navigation.menu import CandidateGoals
from sfw_gym.navigation.planning import PurePursuit, simplify_path
from sfw_gym.navigation.view import RobotView

#: Commands as (linear, angular) fractions of the robot's limits.
TURN, BACK_OFF = (0.0, 1.0), (-1.0, 0.0)


class GoalDriver:
    """One decision at a time: :meth:`start`, then :meth:`command` before every step until it
    returns None.

    Args:
        finder: The episode's :class:`GoalFinder` (its memory is written: tries, bumps,
            blacklists).
        max_steps: The most steps one decision may take.
        blacklist_radius_cells, blacklist_steps: A goal given up is no goal within this radius
            for this many steps.
    """

    def __init__(
        self,
        finder: GoalFinder,
        max_steps: int,
        blacklist_radius_cells: float = 2.0,
        blacklist_steps: int = 200,
    ) -> None:
        self.finder = finder
        self.max_steps = max_steps
        self.blacklist_radius_cells = blacklist_radius_cells
        self.blacklist_steps = blacklist_steps
        self._slides = 0  # slides along a wall since the last back-off
        self.follower = PurePursuit()
        self._queue: list[tuple[float, float]] = []
        self._driving = False
        self._last: tuple[float, np.ndarray] | None = None  # the last drive command, from where
        self.steps, self._start_step = 0, 0
        self.target = (0, 0)

    def reset(self) -> None:
        """A new episode (call after the finder's reset): the frontier agent's follower."""
        self.follower = PurePursuit(lookahead_m=0.4, goal_tolerance_m=self.finder.goal_tolerance_m)
        self._queue, self._driving = [], False
        self._slides = 0

    def start(self, view: RobotView, menu: CandidateGoals, i: int) -> bool:
        """Drive to candidate ``i`` of ``menu``; False (and one step turning in place) when it is
        no valid candidate."""
        self.steps, self._start_step = 0, self.finder.step
        if i >= len(menu) or not menu.valid[i]:
            self._queue, self._driving = [TURN], False
            return False
        self.target = (int(menu.target_rc[i, 0]), int(menu.target_rc[i, 1]))
        cells = menu.path(i)
        xy = view.grid.cell_to_world(cells) if len(cells) else view.xy[None]
        self.follower.set_path(simplify_path(xy, 0.2))
        self.finder.note_tried(self.target, self.blacklist_radius_cells)
        self._queue, self._driving, self._last = [], True, None
        return True

    def command(self, view: RobotView) -> tuple[float, float] | None:
        """The next command given the robot's view now, or None: the decision is over."""
        if self._queue:
            self.steps += 1
            return self._queue.pop(0)
        if not self._driving:
            return None
        if self._last is not None:  # how the last step went
            linear, before = self._last
            if self._resolved(view):
                return self._finish(view, reached=False)
            if view.bumped:
                wanted = linear * view.max_linear_speed_m_s * view.control_period_s
                ahead = wanted > 0 and np.linalg.norm(view.xy - before) < 0.5 * wanted
                if ahead:  # a wall ahead: remembered
                    self.finder.mark_bump(view)
                else:
                    self._slides += 1
                # back off from a wall ahead, and at every third slide along one
                if (ahead or self._slides >= 3) and view.action_type == "continuous":
                    self._slides = 0
                    self._queue.append(BACK_OFF)
                return self._finish(view, reached=False)
            if self.steps >= self.max_steps:
                return self._finish(view, reached=False)
        linear, angular = self.follower.command(view.odometry_pose)
        if not self.follower.has_path:
            return self._finish(view, reached=True)
        self._last = (linear, view.xy)
        self.steps += 1
        return linear, angular

    def _finish(self, view: RobotView, reached: bool) -> tuple[float, float] | None:
        self._driving = False
        steps = self.steps + len(self._queue)  # a back-off step counts
        if (reached or steps >= self.max_steps) and not self._resolved(view):
            # there (or out of time) and still unknown: no goal here for a while
            until = self._start_step + steps + self.blacklist_steps
            self.finder.blacklist(self.target, self.blacklist_radius_cells, until)
        if self.steps == 0:
            self._queue.append(TURN)  # already there: one step turning
        return self.command(view)

    def _resolved(self, view: RobotView) -> bool:
        return resolved(view, self.target)


def resolved(view: RobotView, cell: tuple[int, int]) -> bool:
    """Whether the belief at ``cell`` is no longer unknown (a wall or free)."""
    value = int(view.belief_u8[cell])
    return value <= U8_WALL_MAX or value >= U8_FREE_MIN
