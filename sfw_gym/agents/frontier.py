"""Frontier exploration (Yamauchi 1997) in explore_lite's form, adapted to an RSSI-built map.

A frontier is an unknown cell next to a believed-free cell of the thresholded belief; frontier
cells are grouped into 8-connected clusters (:func:`scipy.ndimage.label`). Each reachable cluster
gets explore_lite's utility ``gain_scale · size_m − potential_scale · path_m``, where ``path_m`` is
the cost-weighted path distance from the robot (unknown cells cost more than free ones, believed
walls are obstacles with a soft inflation by the robot's radius, turning towards the goal costs a
little) to the cheapest place from which the robot resolves one of the cluster's cells.

What differs from a LiDAR map, and how the agent deals with it. The mapper updates cells along
the ray from the strongest router to the robot, between trajectory points with equal k, and marks
the robot's footprint free; there is no range sensor. So:

- unknown space is everywhere, also behind the robot, and the frontier is long and fragmented;
- the cells beside walls are never on a ray piece between two trajectory points in the same
  room, so only the footprint resolves them: the robot must *come within its radius* of a
  frontier cell, not merely see it. A goal is therefore the reachable cell whose footprint covers
  the chosen frontier cell, and exploration crawls along walls the way a wall-follower would,
  while the rays fill the rooms' interiors. A goal reached whose target stayed unknown is a wall:
  blacklisted;
- walls are found by bumping: unknown space is traversable (at a cost); a bump while driving
  forward marks the contact region as an obstacle, backs off one step and replans; frontier
  cells near a bump are walls, not goals; a goal is blacklisted after ``max_bumps_per_goal``;
- small unknown pockets enclosed by known cells (blurred wall estimates inside rooms) lead
  nowhere and fill in as the robot passes: they are not goals.

A goal that makes no progress for ``progress_timeout_steps`` steps is blacklisted (for
``blacklist_ttl_steps``); a cluster the planner cannot reach is blacklisted at once (for
``unreachable_ttl_steps``: the map may open a way later). When no frontier is left, or every one
is blacklisted, the agent records why in ``stop_reason`` and does not stall: while frontiers are
left that are only walled off on its map or lie by bumps, it doubts the map (walls cost instead
of block) and tries the cheapest (an ``escape`` goal: a doorway that blurred or bump-made walls
closed opens up again). The same escape reaches *hidden rooms*: unknown regions enclosed by
believed walls (a room whose doorway the map closed has no frontier at all), found as
room-deep unknown pockets within the explored extent; the goal is the pocket's deepest cell, so
the path crosses the map's walls where they are thinnest. Else it sweeps, driving to the
reachable unknown cell farthest from its path so far.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy import ndimage

from sfw_gym.agents.base import Agent, AgentSettings, RobotView
from sfw_gym.core.config import setting, setting_of
from sfw_gym.core.constants import U8_FREE_MIN, U8_WALL_MAX
from sfw_gym.navigation.candidates import CandidateSettings, GoalFinder
from sfw_gym.navigation.menu import (
    GAIN_SCALE,
    POTENTIAL_SCALE,
    CandidateGoals,
    explore_lite_choice,  # noqa: F401  (re-exported: the teacher's choice, by its old home)
)
from sfw_gym.navigation.planning import (
    SEARCH_RADIUS_M,
    CostField,
    PurePursuit,
    belief_classes,
    cost_field,
    mark_disk,
    simplify_path,
)


@dataclass
class Goal:
    """The goal being pursued.

    Attributes:
        cell: Where the robot drives, ``(row, col)``.
        target: The cell it means to resolve (a frontier cell), or the goal cell itself.
        kind: ``"frontier"``, ``"sweep"`` or a subclass's own kind.
        waypoints: Cells to drive to next, in order, once ``cell`` is reached (a committed
            route: periodic replanning re-paths to the current cell instead of re-choosing).
    """

    cell: tuple[int, int]
    target: tuple[int, int]
    kind: str
    waypoints: list[tuple[int, int]] = field(default_factory=list)
    best_remaining_m: float = np.inf
    steps_without_progress: int = 0
    bumps: int = 0


#: The menu columns that explore_lite's utility reads.
_FRONTIER_FEATURES = ("path_cost_m", "heading_change_rad", "cluster_size_m")

#: What :meth:`FrontierAgent._choose_goal` returns when a bounded search cannot prove its choice.
_UNCERTAIN = Goal((-1, -1), (-1, -1), "uncertain")


@dataclass(frozen=True)
class FrontierSettings(AgentSettings):
    """The parameters of :class:`FrontierAgent`.

    Attributes:
        gain_scale: Weight of a cluster's size (metres of frontier) in its utility.
        potential_scale: Weight of the path distance (metres) to it.
        min_frontier_size_m: Clusters shorter than this (cells × resolution) are ignored.
        progress_timeout_steps: Steps without getting 5 cm closer to a goal before it is
            blacklisted.
        blacklist_radius_m: Frontier cells this close to a blacklisted goal are skipped.
        replan_every_steps: Re-pick the goal at least this often, as the map changes
            (explore_lite's ``planner_frequency``: its 0.33 Hz default is 15 of our 0.2 s steps).
        replan_when_resolved: Also re-pick as soon as the frontier cell being driven to is
            resolved (else the robot drives on to it until the next periodic replan or until it
            arrives, as explore_lite does).
        search_radius_m: Each replan first searches paths up to this cost (m). The choice is
            kept only if no cluster beyond could have a higher utility (a cluster at least this
            far costs at least this much), so it is the goal a full search would pick; else the
            search covers the whole map. One difference remains: walled-off clusters are found
            (and blacklisted for ``unreachable_ttl_steps``) only by full searches.
        unknown_cost: Planner cost of an unknown cell (a free one costs 1).
        bump_exclusion_m: Frontier cells this close to a bump are not goals (walls).
        lookahead_m: Pure-pursuit carrot distance.
        backoff_steps: Steps of reversing after a bump (continuous actions only).
        turn_cost_m_per_rad: Path metres charged per radian of turning towards a goal, so that
            the robot sweeps on instead of turning back and forth.
        max_bumps_per_goal: A goal is blacklisted after this many bumps on the way to it.
        blacklist_ttl_steps: A failed goal stays blacklisted this long (then it is tried again:
            the map around it has changed).
        unreachable_ttl_steps: A cluster the planner cannot reach is blacklisted this long (the
            map may open a way later).
        min_unknown_region_m2: Frontier cells of unknown pockets smaller than this (enclosed by
            known cells) are not goals: they lead nowhere and fill in as the robot passes by.
        escape_wall_cost: When no frontier is left to drive to (none, or every one walled off
            on the map or lying by a bump), the agent plans once more with believed walls
            costing this much per cell (bumps 4×) instead of blocking, and drives to the
            cheapest frontier cell or hidden room (see the module doc) that has not failed as a
            goal: a doorway the map closed by mistake opens up; a real wall ends in bumps and a
            blacklisted goal.
        min_hidden_room_depth_m: Unknown pockets this deep (see :func:`hidden_rooms`) are
            escape goals.
        escape_blacklist_radius_m: A failed escape goal blacklists the cells this close.
        stall_steps, stall_gain_m2: The exploration has stalled when the map grew by less than
            ``stall_gain_m2`` over the last ``stall_steps`` steps; the agent then drives to the
            cheapest hidden room, if there is one, before it takes frontier goals again.
    """

    gain_scale: float = setting(GAIN_SCALE, ge=0.0)
    potential_scale: float = setting(POTENTIAL_SCALE, ge=0.0)
    min_frontier_size_m: float = setting_of(CandidateSettings, "min_frontier_size_m")
    progress_timeout_steps: int = setting(30, integer=True, ge=1)
    blacklist_radius_m: float = setting(0.3, ge=0.0)
    replan_every_steps: int = setting(5, integer=True, ge=1)
    replan_when_resolved: bool = setting(True, choices=(True, False))
    search_radius_m: float = setting(SEARCH_RADIUS_M, gt=0.0)
    unknown_cost: float = setting_of(CandidateSettings, "unknown_cost")
    bump_exclusion_m: float = setting_of(CandidateSettings, "bump_exclusion_m")
    lookahead_m: float = setting(0.4, ge=0.05)
    backoff_steps: int = setting(1, integer=True, ge=0)
    turn_cost_m_per_rad: float = setting_of(CandidateSettings, "turn_cost_m_per_rad")
    max_bumps_per_goal: int = setting(2, integer=True, ge=1)
    blacklist_ttl_steps: int = setting(600, integer=True, ge=1)
    unreachable_ttl_steps: int = setting(200, integer=True, ge=1)
    min_unknown_region_m2: float = setting_of(CandidateSettings, "min_unknown_region_m2")
    escape_wall_cost: float = setting(25.0, ge=1.0)
    min_hidden_room_depth_m: float = setting_of(CandidateSettings, "min_hidden_room_depth_m")
    escape_blacklist_radius_m: float = setting(1.0, ge=0.0)
    stall_steps: int = setting(300, integer=True, ge=1)
    stall_gain_m2: float = setting(1.0, ge=0.0)


class FrontierAgent(Agent):
    """Frontier exploration with explore_lite's utility, a grid planner and pure pursuit.

    Parameters: :class:`FrontierSettings` (keyword arguments, checked).
    """

    name = "frontier"
    #: Goal kinds that periodic replanning re-paths to instead of re-choosing.
    _committed_kinds: tuple[str, ...] = ()
    #: Whether :meth:`_choose_goal` can prove its choice on a bounded search (explore_lite's
    #: utility falls with the path's cost; the subclasses' menus need every cost).
    _bounded_search = True

    settings_class = FrontierSettings
    settings: FrontierSettings

    # -- episode ---------------------------------------------------------------------------------
    def _on_reset(self, view: RobotView) -> None:
        res = view.grid.resolution_m
        self.visited = np.zeros(view.grid.shape, bool)  # within the robot's radius of its path
        self.finder = GoalFinder(self._candidate_settings())
        self.finder.reset(view)
        self._res = res
        self._visit_radius_cells = view.radius_m / res
        self.goal: Goal | None = None
        self.follower = PurePursuit(
            lookahead_m=self.settings.lookahead_m, goal_tolerance_m=self.finder.goal_tolerance_m
        )
        self._since_plan = 0
        self._path_cells: tuple[np.ndarray, np.ndarray] = (np.zeros(0, int), np.zeros(0, int))
        self._backoff = 0
        self._slides = 0
        self._last_xy = view.xy
        self._known_log: list[tuple[int, int]] = []
        self.n_blacklisted = 0
        self.n_goals = 0
        self.n_bumps = 0
        self.n_plans = 0
        self.n_full_searches = 0
        self.candidates: list[tuple[tuple[int, int], float]] = []

    def _candidate_settings(self) -> CandidateSettings:
        return CandidateSettings(
            unknown_cost=self.settings.unknown_cost,
            min_frontier_size_m=self.settings.min_frontier_size_m,
            bump_exclusion_m=self.settings.bump_exclusion_m,
            min_unknown_region_m2=self.settings.min_unknown_region_m2,
            turn_cost_m_per_rad=self.settings.turn_cost_m_per_rad,
            min_hidden_room_depth_m=self.settings.min_hidden_room_depth_m,
        )

    def _act(self, view: RobotView, obs: Any) -> tuple[float, float]:
        self.finder.set_step(self.steps)
        mark_disk(self.visited, view.cell, self._visit_radius_cells)
        # A bump that stopped the robot driving forward: remember a wall ahead, back off
        # (continuous) and replan. Contact while turning or reversing, or while sliding along
        # a wall (brushing a door frame), says little about what lies ahead: replan only, and
        # back off if the sliding goes on (3 steps).
        moved = float(np.linalg.norm(view.xy - self._last_xy))
        wanted = self.last_command[0] * view.max_linear_speed_m_s * view.control_period_s
        bumped_ahead = view.bumped and wanted > 0 and moved < 0.5 * wanted
        slid = view.bumped and wanted > 0 and not bumped_ahead
        self._slides = self._slides + 1 if slid else 0
        self._last_xy = view.xy
        if bumped_ahead:
            self._mark_bump(view)
        if bumped_ahead or self._slides >= 3:
            self._slides = 0
            if self.action_type == "continuous" and self.settings.backoff_steps:
                self._backoff = self.settings.backoff_steps
        self._track_progress(view, bumped_ahead)
        if self._backoff > 0:
            self._backoff -= 1
            self.follower.set_path(np.zeros((0, 2)))
            return -1.0, 0.0
        if self._needs_plan(view, bumped_ahead or slid):
            self._plan(view)
        self._since_plan += 1
        for _ in range(2):
            if not self.follower.has_path:  # nothing to drive to: turn, never stand still
                return 0.0, 1.0
            linear, angular = self.follower.command(view.odometry_pose)
            if self.follower.has_path:
                return linear, angular
            self._arrived(view)  # reached the goal cell this step: the next goal at once
        return linear, angular

    def _arrived(self, view: RobotView) -> None:
        """The goal cell is reached: on to the next waypoint, or blacklist an unresolved target."""
        goal = self.goal
        if goal is not None and goal.waypoints:
            nxt = goal.waypoints.pop(0)
            goal.cell = goal.target = nxt
            goal.best_remaining_m, goal.steps_without_progress, goal.bumps = np.inf, 0, 0
            self._plan(view)
            return
        if (
            goal is not None
            and goal.kind in ("frontier", "escape")
            and self._still_unknown(view, goal.target)
        ):
            self._blacklist(goal)  # the footprint covered it and it stayed unknown: a wall
        self.goal = None
        self._plan(view)

    def _track_progress(self, view: RobotView, bumped: bool) -> None:
        """Blacklist the goal after ``progress_timeout_steps`` without progress or
        ``max_bumps_per_goal`` bumps on the way."""
        goal = self.goal
        if goal is None:
            return
        goal.bumps += int(bumped)
        remaining = float(np.linalg.norm(view.xy - view.grid.cell_to_world(np.asarray(goal.cell))))
        if remaining < goal.best_remaining_m - 0.05:
            goal.best_remaining_m = remaining
            goal.steps_without_progress = 0
        else:
            goal.steps_without_progress += 1
        if (
            goal.steps_without_progress >= self.settings.progress_timeout_steps
            or goal.bumps >= self.settings.max_bumps_per_goal
        ):
            self._blacklist(goal)
            self.follower.set_path(np.zeros((0, 2)))

    def _needs_plan(self, view: RobotView, bumped: bool) -> bool:
        """Replan on events: no goal or path, a bump, the path blocked by a new wall, the
        frontier target resolved; else every ``replan_every_steps`` as the map changes."""
        goal = self.goal
        if goal is None or bumped or not self.follower.has_path:
            return True
        if self._since_plan >= self.settings.replan_every_steps or self._path_blocked(view):
            return True
        return (
            self.settings.replan_when_resolved
            and goal.kind == "frontier"
            and not self._still_unknown(view, goal.target)
        )

    def _path_blocked(self, view: RobotView) -> bool:
        """Whether a cell of the current path has become a believed wall or a bump."""
        rows, cols = self._path_cells
        if not len(rows):
            return False
        return bool(
            (view.belief_u8[rows, cols] <= U8_WALL_MAX).any() or self.finder.bumps[rows, cols].any()
        )

    @staticmethod
    def _still_unknown(view: RobotView, cell: tuple[int, int]) -> bool:
        return U8_WALL_MAX < int(view.belief_u8[cell[0], cell[1]]) < U8_FREE_MIN

    # -- bookkeeping -----------------------------------------------------------------------------
    def _blacklist(self, goal: Goal) -> None:
        """Blacklist the cells within ``blacklist_radius_m`` of the goal's target."""
        radius_m = self.settings.escape_blacklist_radius_m if goal.kind == "escape" else None
        res_cells = (radius_m or self.settings.blacklist_radius_m) / self._res
        self.finder.blacklist(
            goal.target, max(res_cells, 0.5), self.steps + self.settings.blacklist_ttl_steps
        )
        self.n_blacklisted += 1
        self.goal = None

    def _mark_bump(self, view: RobotView) -> None:
        """Remember a wall where the bumper fired."""
        self.finder.mark_bump(view)
        self.n_bumps += 1

    @property
    def bumps(self) -> np.ndarray:
        """Contact regions (where the bumper fired), ``[row, col]``."""
        return self.finder.bumps

    @property
    def unreachable_until(self) -> np.ndarray:
        """Step until which each cell is a walled-off frontier cell."""
        return self.finder.unreachable_until

    @property
    def blacklisted(self) -> np.ndarray:
        """Cells blacklisted now (failed goals, walled-off frontiers), ``[row, col]``."""
        return self.finder.failed | self.finder.unreachable

    @property
    def unreachable(self) -> np.ndarray:
        """Frontier cells that the planner found walled off (blacklisted for a while)."""
        return self.finder.unreachable

    @property
    def _reach_offsets(self) -> np.ndarray:
        return self.finder.reach_offsets

    # -- planning --------------------------------------------------------------------------------
    def _costs(self, view: RobotView, relaxed: bool = False) -> np.ndarray:
        """Planner costs; ``relaxed``: believed walls and bumps cost ``escape_wall_cost``."""
        return self.finder.costs(view, self.settings.escape_wall_cost if relaxed else None)

    def _plan(self, view: RobotView) -> None:
        """Pick a goal and a path to it (or fall back to sweeping); re-path a committed goal."""
        self._since_plan = 0
        self.n_plans += 1
        goal = self.goal
        relaxed = goal is not None and goal.kind == "escape"
        committed = goal is not None and goal.kind in (*self._committed_kinds, "escape")
        costs = self._costs(view, relaxed)
        res = view.grid.resolution_m
        # A bounded first search, unless there is no frontier to prove a choice about.
        bounded = self._bounded_search and not committed and self.finder.frontier(view).any()
        bound = self.settings.search_radius_m if bounded else np.inf
        paths = cost_field(costs, view.cell, res, max_cost_m=bound)
        if committed:
            assert goal is not None
            if np.isfinite(paths.cumulative[goal.cell]):
                self._set_goal(view, paths, goal)
                return
            self._blacklist(goal)
        stalled = self._stalled(view)
        goal = None if stalled else self._choose_goal(view, paths)
        if not paths.complete and (goal is None or goal is _UNCERTAIN):
            # The bounded search could not prove its choice (or found none): search everywhere.
            self.n_full_searches += 1
            paths = cost_field(costs, view.cell, res)
            goal = None if stalled else self._choose_goal(view, paths)
        if goal is None:
            # No frontier to drive to (or the map stopped growing), yet unknown space may hide
            # behind the map's walls (a doorway closed by blurred or bump-made walls). Doubt
            # them: walls cost, not block.
            escape = cost_field(self._costs(view, True), view.cell, view.grid.resolution_m)
            goal = self._escape_goal(view, escape, rooms_only=stalled)
            if goal is not None:
                paths = escape
            elif stalled:
                goal = self._choose_goal(view, paths)
        if goal is None:
            goal = self._sweep_goal(view, paths)
        self._set_goal(view, paths, goal)

    def _stalled(self, view: RobotView) -> bool:
        """Whether the map grew by less than ``stall_gain_m2`` over the last ``stall_steps``."""
        b = view.belief_u8
        known = int(np.count_nonzero(b <= U8_WALL_MAX)) + int(np.count_nonzero(b >= U8_FREE_MIN))
        self._known_log.append((self.steps, known))
        while (
            len(self._known_log) > 1
            and self._known_log[1][0] <= self.steps - self.settings.stall_steps
        ):
            self._known_log.pop(0)
        step0, known0 = self._known_log[0]
        grown_m2 = (known - known0) * view.grid.resolution_m**2
        return (
            self.steps - step0 >= self.settings.stall_steps
            and grown_m2 < self.settings.stall_gain_m2
        )

    def _escape_goal(
        self, view: RobotView, paths: CostField, rooms_only: bool = False
    ) -> Goal | None:
        """The cheapest frontier cell or hidden room's deepest cell (not a failed goal; only
        hidden rooms with ``rooms_only``) on a map whose walls merely cost."""
        mask = np.zeros(view.grid.shape, bool)
        if not rooms_only:
            mask |= self.finder.frontier(view) & ~self.finder.failed
        rooms, _, _ = self.finder.hidden_room_targets(view)
        mask[rooms[:, 0], rooms[:, 1]] = True
        approach = np.where(mask, self._approach(paths), np.inf)
        if not np.isfinite(approach).any():
            return None
        r, c = np.unravel_index(int(np.argmin(approach)), approach.shape)
        target = (int(r), int(c))
        return Goal(self._approach_cell(paths, target), target, "escape")

    def _set_goal(self, view: RobotView, paths: CostField, goal: Goal | None) -> None:
        prev = self.goal
        if goal is None:
            self.goal = None
            self.follower.set_path(np.zeros((0, 2)))
            return
        if prev is goal:
            pass
        elif prev is not None and prev.kind == goal.kind and prev.target == goal.target:
            goal.best_remaining_m = prev.best_remaining_m  # same goal: keep its progress clock
            goal.steps_without_progress = prev.steps_without_progress
            goal.bumps = prev.bumps
        else:
            self.n_goals += 1
            self.finder.note_tried(
                goal.target, max(self.settings.blacklist_radius_m / self._res, 0.5)
            )
        self.goal = goal
        cells = paths.path(goal.cell)
        # Cells that were passable when planned (the start may be inside an inflated wall).
        passable = view.belief_u8[cells[:, 0], cells[:, 1]] > U8_WALL_MAX
        self._path_cells = (cells[passable, 0], cells[passable, 1])
        xy = view.grid.cell_to_world(cells) if len(cells) else view.xy[None]
        self.follower.set_path(simplify_path(xy, 0.2))

    def _approach(self, paths: CostField) -> np.ndarray:
        """Per cell: the cheapest path cost to a cell whose footprint covers it."""
        return self.finder.approach(paths)

    def _approach_cell(self, paths: CostField, target: tuple[int, int]) -> tuple[int, int]:
        """The cheapest reachable cell whose footprint covers ``target``."""
        return self.finder.approach_cell(paths, target)

    def _frontier_exclusion(self, view: RobotView) -> np.ndarray:
        """Cells that are not frontier goals (see :meth:`GoalFinder.exclusion`)."""
        return self.finder.exclusion(view)

    def _choose_goal(self, view: RobotView, paths: CostField) -> Goal | None:
        """The frontier cluster of best utility on the finder's menu (explore_lite)."""
        self.candidates = []
        if not self.finder.frontier(view).any():
            self._stop("no_frontiers")
            return None
        menu = self.finder.find(view, paths, sources=("frontier",), features=_FRONTIER_FEATURES)
        cost = menu.feature("path_cost_m") + self.settings.turn_cost_m_per_rad * menu.feature(
            "heading_change_rad"
        )
        # A cluster's cost (path + turn) is exact when it is within the search's bound: every
        # cell beyond costs at least the bound. Else it could cost as little as the bound.
        exact = paths.complete | (cost <= paths.max_cost_m)
        far = np.flatnonzero(~exact)
        bound = np.full(len(far), paths.max_cost_m)
        beyond = self._menu_utilities(view, menu, far, bound).max(initial=-np.inf)
        for i in np.flatnonzero(exact & ~menu.valid):  # walled off on the belief map
            self.finder.mark_unreachable(
                menu.clusters[int(i)], self.steps + self.settings.unreachable_ttl_steps
            )
            self.n_blacklisted += 1
        ok = np.flatnonzero(exact & menu.valid)
        u = self._menu_utilities(view, menu, ok, cost[ok])
        self.candidates = list(
            zip(map(tuple, menu.target_rc[ok].tolist()), u.tolist(), strict=True)
        )
        if u.max(initial=-np.inf) < beyond:
            return _UNCERTAIN  # a cluster beyond the search might be better: search everywhere
        if not len(ok):
            self._stop("all_blacklisted")
            return None
        best = int(ok[np.argmax(u)])  # the first of equal utilities
        self._log_decision(menu, best)
        self._resume()
        target = (int(menu.target_rc[best, 0]), int(menu.target_rc[best, 1]))
        return Goal((int(menu.goal_rc[best, 0]), int(menu.goal_rc[best, 1])), target, "frontier")

    def _utility(self, view: RobotView, cluster: np.ndarray, path_m: float) -> float:
        """explore_lite's utility of a frontier cluster (its ``(N, 2)`` cells) at ``path_m``."""
        return float(self._utilities(view, [cluster], np.array([path_m]))[0])

    def _menu_utilities(
        self, view: RobotView, menu: CandidateGoals, index: np.ndarray, path_m: np.ndarray
    ) -> np.ndarray:
        """:meth:`_utilities` of the menu's candidates ``index`` at ``path_m``: from the
        clusters' sizes on the menu, unless a subclass weighs the clusters' cells."""
        if type(self)._utilities is FrontierAgent._utilities:
            return self._size_utilities(menu.feature("cluster_size_m")[index], path_m)
        return self._utilities(view, [menu.clusters[i] for i in index], path_m)

    def _utilities(
        self, view: RobotView, clusters: list[np.ndarray], path_m: np.ndarray
    ) -> np.ndarray:
        """:meth:`_utility` of each cluster at its ``path_m``."""
        size_m = np.array([len(c) for c in clusters], np.int64) * view.grid.resolution_m
        return self._size_utilities(size_m, path_m)

    def _size_utilities(self, size_m: np.ndarray, path_m: np.ndarray) -> np.ndarray:
        """explore_lite's utility of clusters of ``size_m`` metres at ``path_m``."""
        gain = self.settings.gain_scale * np.asarray(size_m, np.float64)
        return gain - self.settings.potential_scale * np.asarray(path_m, np.float64)

    def _sweep_goal(self, view: RobotView, paths: CostField) -> Goal | None:
        """Fallback: the reachable cell farthest from the path so far (keeps the rays sweeping)."""
        free, _, unknown = belief_classes(view.belief_u8)
        target = paths.reachable() & (free | unknown) & ~self.visited & ~self.blacklisted
        if not target.any():
            return None
        far = ndimage.distance_transform_edt(~self.visited)
        score = np.where(target, far + 1e3 * unknown, -1.0)
        r, c = np.unravel_index(int(np.argmax(score)), score.shape)
        cell = (int(r), int(c))
        return Goal(cell, cell, "sweep")
