"""The coverage oracle: a tour through the cells still unknown, planned on the true plan.

Privileged (:mod:`sfw_gym.agents.oracles`): it reads the true plan, pose and radio. Every replan
it scores candidate cells of the true free space (where the robot fits) by the bits the mapper
could gain there, divided by the true shortest path's cost plus an offset, and drives the true
shortest path to the best one with pure pursuit on the true pose: no searching, no detours
through believed walls, no goals behind unseen walls. Its paths may run a robot's radius from a
wall (``margin_m`` 0), where the footprint reaches the cells along it; it brushes walls there, a
third as often as frontier bumps (docs/results/ceiling.md). On a drifting-odometry env it is
no ceiling: the belief it reads is drawn in the drifting frame, and it plans in the true one.

Three variants each give up one piece of that knowledge, to tell where the ceiling lives
(``plan_on``, ``targets_from``, ``gain_from``; registered as ``oracle-belief-paths``,
``oracle-frontier-targets`` and ``oracle-belief-gain``): paths planned on the belief (unknown
cells passable, believed walls not: bumps and detours as a robot has them), targets among the
belief's frontier cells only, or the gain counted on the belief alone (the ray towards the
nearest router, ending at the first believed wall).

The gain at a cell is the entropy of the belief's unknown cells the robot would resolve there:
its footprint (the mapper's rule 1), and the stretch of the ray towards the router that is truly
strongest there (the one the mapper updates), from the cell back to the first true wall: the
cells that line-of-sight readings, or two readings with equal k on that ray, mark free (a
stretch with a wall between it and the router counts ``blocked_ray_weight`` of its bits).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numba import njit

from sfw_gym.agents.base import AgentSettings, Decision, RobotView
from sfw_gym.agents.oracles import OracleAgent
from sfw_gym.core.config import setting
from sfw_gym.core.constants import U8_FREE_MIN
from sfw_gym.mapping.grid import belief_classes
from sfw_gym.navigation.candidates import (
    footprint_bits,
    ray_buffer,
    ray_cells,
    unknown_bits_at,
)
from sfw_gym.navigation.frontiers import frontier_mask
from sfw_gym.navigation.menu import FEATURES
from sfw_gym.navigation.planning import (
    PurePursuit,
    WallBand,
    cells_to_world,
    cost_field,
    disk_offsets,
    free_start,
    mark_disk,
    wall_cost_term,
    wall_distance_m,
)

#: Where a piece of the oracle's knowledge comes from.
KNOWLEDGE = ("truth", "belief")
#: The oracle's decisions carry no menu features.
NO_FEATURES = np.full(len(FEATURES), np.nan)
NO_FEATURES.flags.writeable = False


@dataclass(frozen=True)
class CoverageOracleSettings(AgentSettings):
    """The parameters of :class:`CoverageOracle`.

    Attributes:
        replan_every_steps: Choose the next target after this many steps on one (one more when
            it was chosen on arrival, mid-step), and on arrival.
        distance_offset_m: Added to a candidate's path cost (keeps near goals from dominating).
        candidate_stride_cells: Candidates are the free cells of a lattice this many cells apart.
        margin_m: Paths keep this much clearance beyond the robot's radius from true walls.
        lookahead_m: Pure-pursuit carrot distance.
        blocked_ray_weight: The weight of a ray's free stretch when a true wall stands between
            the cell and the router (the mapper marks it free only where another reading on
            that ray has the same k); 1 where the router is in sight.
        plan_on: Where paths are planned: ``"truth"`` (the true plan) or ``"belief"`` (the
            belief map, unknown passable, replanned as it grows; the target is still chosen by
            its true path's cost).
        targets_from: The candidate targets: ``"truth"`` (every true free cell the robot fits
            on) or ``"frontiers"`` (the belief's frontier cells among them: unknown cells beside
            a believed-free one, :func:`~sfw_gym.navigation.frontiers.frontier_mask`).
        gain_from: What the gain reads: ``"truth"`` (the truly strongest router's ray, ending
            at the first true wall) or ``"belief"`` (the nearest router's ray, ending at the
            first believed wall).
    """

    replan_every_steps: int = setting(10, integer=True, ge=1)
    distance_offset_m: float = setting(1.0, ge=0.01)
    candidate_stride_cells: int = setting(1, integer=True, ge=1)
    margin_m: float = setting(0.0, ge=0.0)
    lookahead_m: float = setting(0.4, ge=0.05)
    blocked_ray_weight: float = setting(0.3, ge=0.0, le=1.0)
    plan_on: str = setting("truth", choices=KNOWLEDGE)
    targets_from: str = setting("truth", choices=("truth", "frontiers"))
    gain_from: str = setting("truth", choices=KNOWLEDGE)


class CoverageOracle(OracleAgent):
    """Expected bits per metre on the true plan, driven on true shortest paths (privileged).

    Parameters: :class:`CoverageOracleSettings` (keyword arguments, checked).

    A cell the robot has stood on (within its radius) is no candidate again (what a reading
    there gives, it has given) until no other cell has anything left to give.

    Attributes:
        target_rc: The cell driven to (None: nothing left to gain).
        n_plans: Replans this episode (each choice of a target is also logged in
            :attr:`decisions`, without menu features).
    """

    name = "oracle-coverage"

    settings_class = CoverageOracleSettings
    settings: CoverageOracleSettings

    def _on_reset(self, view: RobotView) -> None:
        truth = self.ground_truth()
        grid = truth.grid
        res = float(grid.resolution_m)
        free = np.asarray(truth.truth_u8) >= U8_FREE_MIN
        lethal = view.radius_m + self.settings.margin_m
        self._band = WallBand(view.radius_m, lethal_radius_m=lethal)
        self._cost = 1.0 + wall_cost_term(wall_distance_m(~free, res), res, self._band)
        rows, cols = np.nonzero(free)
        centres = grid.cell_to_world(np.stack([rows, cols], axis=1))
        self._zone = np.full(free.shape, -1, np.int64)  # the truly strongest router; -1: wall
        self._zone[rows, cols] = np.argmax(truth.radio.mean_rssi(centres), axis=1)
        stride = self.settings.candidate_stride_cells
        lattice = np.zeros(free.shape, bool)
        lattice[::stride, ::stride] = True
        self._candidates = np.argwhere(lattice & np.isfinite(self._cost))
        self._routers = np.asarray(truth.radio.routers, np.float64)
        self._origin = np.asarray(grid.origin_xy, np.float64)
        self._res = res
        self._footprint = disk_offsets(view.radius_m / res)
        self._radius_m = float(view.radius_m)
        self._grid = grid
        self.follower = PurePursuit(lookahead_m=self.settings.lookahead_m, goal_tolerance_m=res)
        self._visited = np.zeros(free.shape, bool)  # within the robot's radius of its path
        self.target_rc: tuple[int, int] | None = None
        self._since_plan = 0
        self.n_plans = 0

    def gains(self, view: RobotView, cells: np.ndarray) -> np.ndarray:
        """Bits the mapper could gain with the robot standing at each of ``cells`` ``(N, 2)``."""
        return _gains(
            view.log_odds,
            view.belief_u8,
            self._zone if self.settings.gain_from == "truth" else self._belief_zone(view),
            self._routers,
            np.asarray(cells, np.int64).reshape(-1, 2),
            self._footprint,
            self._radius_m,
            self._origin,
            self._res,
            self.settings.blocked_ray_weight,
        )

    def _belief_zone(self, view: RobotView) -> np.ndarray:
        """Each cell's nearest router (a robot's guess of the strongest), -1 where the belief
        holds a wall: the gain's router and where its ray ends, read from the belief alone."""
        x, y = view.grid.cell_centres()
        d2 = (x[..., None] - self._routers[:, 0]) ** 2 + (y[..., None] - self._routers[:, 1]) ** 2
        zone = np.argmin(d2, axis=-1).astype(np.int64)
        zone[belief_classes(view.belief_u8)[1]] = -1
        return zone

    def _candidate_cells(self, view: RobotView) -> np.ndarray:
        """The cells a target may be: all of them, or the belief's frontier cells among them."""
        cells = self._candidates
        if self.settings.targets_from == "truth":
            return cells
        frontier = frontier_mask(view.belief_u8)
        return cells[frontier[cells[:, 0], cells[:, 1]]]

    def _driven_paths(self, view: RobotView, start: tuple[int, int], true_paths: Any) -> Any:
        """The paths the robot drives: on the true plan, or on the belief (believed walls and
        their band impassable, unknown cells passable)."""
        if self.settings.plan_on == "truth":
            return true_paths
        walls = belief_classes(view.belief_u8)[1]
        cost = 1.0 + wall_cost_term(wall_distance_m(walls, self._res), self._res, self._band)
        return cost_field(free_start(cost, start), start, self._res)

    def _act(self, view: RobotView, obs: Any) -> tuple[float, float]:
        pose = self.ground_truth().pose
        mark_disk(self._visited, self._grid.clipped_cell(pose), self._radius_m / self._res)
        if not self.follower.has_path or self._since_plan >= self.settings.replan_every_steps:
            self.plan(view, pose)
        self._since_plan += 1
        linear, angular = self.follower.command(pose)
        if not self.follower.has_path:  # arrived: on to the next target at once
            self.plan(view, pose)
            linear, angular = self.follower.command(pose)
        return linear, angular

    def plan(self, view: RobotView, pose: tuple[float, float, float]) -> None:
        """Choose the target of most bits per metre on the true plan from the true ``pose`` and
        set its path, true or on the belief (:attr:`target_rc`; None when nothing is left to
        gain)."""
        self.n_plans += 1
        self._since_plan = 0
        start = self._grid.clipped_cell(pose)
        paths = cost_field(free_start(self._cost, start), start, self._res)
        driven = self._driven_paths(view, start, paths)
        cells = self._candidate_cells(view)
        metres = paths.cumulative[cells[:, 0], cells[:, 1]]
        reachable = np.isfinite(metres) & np.isfinite(driven.cumulative[cells[:, 0], cells[:, 1]])
        fresh = reachable & ~self._visited[cells[:, 0], cells[:, 1]]
        bits = self.gains(view, cells[fresh])
        if not (bits > 0).any():  # what is left lies where it has been: go round again
            self._visited[:] = False
            fresh = reachable
            bits = self.gains(view, cells[fresh])
        cells, metres = cells[fresh], metres[fresh]
        if not (bits > 0).any():
            self._stop("no_frontiers")
            self.target_rc = None
            self.follower.set_path(np.zeros((0, 2)))
            return
        self._resume()
        i = int(np.argmax(bits / (metres + self.settings.distance_offset_m)))
        self.target_rc = (int(cells[i, 0]), int(cells[i, 1]))
        self.decisions.append(Decision(self.steps, self.target_rc, len(cells), NO_FEATURES))
        self.follower.set_path(cells_to_world(self._grid, driven.path(self.target_rc)))


@njit(cache=True)
def _gain_at(
    log_odds,
    belief,
    zone,
    walls,
    routers,
    r0,
    c0,
    footprint,
    radius,
    origin,
    res,
    seen,
    mark,
    weight,
    buf,
):  # pragma: no cover (compiled)
    """The unknown bits at the robot's footprint on cell (r0, c0) plus those on the ray towards
    its strongest router, from beyond the footprint's ``radius`` to the first truly non-free
    cell (times ``weight`` unless the ray reaches the router); each cell once (``seen`` holds
    ``mark`` where counted)."""
    total = footprint_bits(log_odds, belief, r0, c0, footprint, seen, mark)
    router = routers[zone[r0, c0]]
    cells, reached = ray_cells(r0, c0, router, radius, origin, res, walls, buf)
    ray = 0.0
    for k in range(len(cells)):
        r, c = cells[k, 0], cells[k, 1]
        if seen[r, c] != mark:
            seen[r, c] = mark
            ray += unknown_bits_at(log_odds, belief, r, c)
    return total + (ray if reached else weight * ray)  # a true wall (or the grid's edge)


@njit(cache=True)
def _gains(
    log_odds, belief, zone, routers, cells, footprint, radius, origin, res, weight
):  # pragma: no cover (compiled)
    """:func:`_gain_at` of each cell."""
    seen = np.zeros(belief.shape, np.int64)
    buf = ray_buffer(belief.shape)
    walls = zone < 0
    out = np.zeros(len(cells))
    for i in range(len(cells)):
        r, c = cells[i, 0], cells[i, 1]
        out[i] = _gain_at(
            log_odds,
            belief,
            zone,
            walls,
            routers,
            r,
            c,
            footprint,
            radius,
            origin,
            res,
            seen,
            i + 1,
            weight,
            buf,
        )
    return out


# ---------------------------------------------------------------- where the ceiling lives
@dataclass(frozen=True)
class BeliefPathsSettings(CoverageOracleSettings):
    """:class:`CoverageOracleSettings`, paths planned on the belief."""

    plan_on: str = setting("belief", choices=KNOWLEDGE)


@dataclass(frozen=True)
class FrontierTargetsSettings(CoverageOracleSettings):
    """:class:`CoverageOracleSettings`, targets among the belief's frontier cells."""

    targets_from: str = setting("frontiers", choices=("truth", "frontiers"))


@dataclass(frozen=True)
class BeliefGainSettings(CoverageOracleSettings):
    """:class:`CoverageOracleSettings`, the gain counted on the belief alone."""

    gain_from: str = setting("belief", choices=KNOWLEDGE)


class BeliefPathsOracle(CoverageOracle):
    """The coverage oracle with its paths planned on the belief (privileged: its targets and
    their gains still read the truth)."""

    name = "oracle-belief-paths"
    settings_class = BeliefPathsSettings


class FrontierTargetsOracle(CoverageOracle):
    """The coverage oracle with its targets among the belief's frontier cells (privileged: their
    gains and paths still read the truth)."""

    name = "oracle-frontier-targets"
    settings_class = FrontierTargetsSettings


class BeliefGainOracle(CoverageOracle):
    """The coverage oracle with the gain at a target counted on the belief alone (privileged:
    its candidates and paths still read the truth)."""

    name = "oracle-belief-gain"
    settings_class = BeliefGainSettings
