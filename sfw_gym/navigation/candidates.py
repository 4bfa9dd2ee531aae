"""Candidate goals: one menu of places worth driving to, shared by every exploring agent.

:func:`candidate_goals` returns, for the current belief, up to K goals with a reachable path on the
belief map, a feature vector (:data:`FEATURES`, units in the names) and a validity mask. The
candidates come from three sources (:data:`SOURCES`):

- ``frontier``: one per frontier cluster (explore_lite): the cluster cell that is cheapest to
  resolve, counting the path to a cell whose footprint covers it and the turn towards it;
- ``hidden_room``: the deepest cell of each room-deep unknown pocket inside the explored extent
  (a room whose doorway the map closed has no frontier);
- ``info_gain``: frontier cells (an even subsample) scored by the bits the mapper would gain with
  the robot there (next-best-view).

:class:`GoalFinder` is the stateful form that agents keep for an episode: it remembers bumps,
failed and unreachable goals and how often a place was tried, and it caches what changes slowly
(frontier cells are updated only where the belief changed since the last call; the distance to
walls only when the walls change). One shortest-path field (:func:`cost_field`) per replan
serves every candidate.

The menu itself (:class:`~sfw_gym.navigation.menu.CandidateGoals`) and the choices made on it
(explore_lite's utility, the greedy bits per metre, the teachers) are in
:mod:`sfw_gym.navigation.menu`, re-exported here by their old home; the compiled frontier
analysis the menu starts from (open frontier cells, their clusters and best cells, pockets) is in
:mod:`sfw_gym.navigation.frontiers`.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit
from scipy import ndimage

from sfw_gym.core.angles import wrap_angle
from sfw_gym.core.config import Config, setting
from sfw_gym.core.constants import NOT_HEARD_DBM, U8_FREE_MIN, U8_WALL_MAX
from sfw_gym.mapping.grid import belief_classes
from sfw_gym.mapping.sparse import cell_entropy_bits
from sfw_gym.navigation.frontiers import (
    EIGHT_CONNECTED,
    excluded_cells,
    frontier_mask,
    frontier_menu,
    hidden_rooms,
    update_frontier,
)
from sfw_gym.navigation.menu import (
    _F,
    FEATURES,
    GAIN_SCALE,
    GREEDY_OFFSET_M,
    POTENTIAL_SCALE,
    SOURCES,
    TEACHERS,
    TURN_COST_M_PER_RAD,
    CandidateGoals,
    bits_per_metre,
    explore_lite_choice,
    explore_lite_utilities,
    greedy_choice,
    proven_on_bounded_paths,
)
from sfw_gym.navigation.planning import (
    FREE_START_COST,
    CostField,
    WallBand,
    cost_field,
    disk_cells,
    disk_offsets,
    free_start,
    mark_contact,
    min_over_offsets,
    update_wall_cost_term,
    wall_cost_term,
    wall_distance_m,
)
from sfw_gym.navigation.radio_zones import router_scores
from sfw_gym.navigation.view import RobotView

__all__ = [
    "FEATURES",
    "GAIN_SCALE",
    "GREEDY_OFFSET_M",
    "POTENTIAL_SCALE",
    "SOURCES",
    "TEACHERS",
    "TURN_COST_M_PER_RAD",
    "CandidateGoals",
    "CandidateSettings",
    "GoalFinder",
    "bits_per_metre",
    "candidate_goals",
    "explore_lite_choice",
    "explore_lite_utilities",
    "footprint_bits",
    "greedy_choice",
    "proven_on_bounded_paths",
    "ray_buffer",
    "ray_cells",
    "unknown_bits_at",
]


@dataclass(frozen=True)
class CandidateSettings(Config):
    """How candidates are found (the defaults are :class:`~sfw_gym.agents.FrontierAgent`'s)."""

    prefix: ClassVar[str | None] = ""
    unknown_cost: float = setting(1.5, ge=1.0)
    min_frontier_size_m: float = setting(0.3, ge=0.0)
    bump_exclusion_m: float = setting(0.3, ge=0.0)
    min_unknown_region_m2: float = setting(0.5, ge=0.0)
    turn_cost_m_per_rad: float = setting(TURN_COST_M_PER_RAD, ge=0.0)
    min_hidden_room_depth_m: float = setting(0.5, ge=0.0)
    info_gain_samples: int = setting(300, integer=True, ge=1)
    near_radius_m: float = setting(1.0, gt=0.0)
    zones_every_steps: int = setting(25, integer=True, ge=1)


def candidate_goals(view: RobotView, max_candidates: int = 32, **settings) -> CandidateGoals:
    """Up to ``max_candidates`` goals for ``view``'s belief (a fresh :class:`GoalFinder`).

    Slots go to the sources in turn: frontier clusters (best explore_lite utility first) up to
    three quarters, hidden rooms (cheapest first) up to an eighth, the rest to information-gain
    points (most bits per metre first); slots a source leaves empty go to the others.

    Args:
        view: What the robot knows.
        max_candidates: K.
        **settings: Fields of :class:`CandidateSettings`.
    """
    finder = GoalFinder(CandidateSettings.from_dict(settings, "candidate_goals"))
    finder.reset(view)
    paths = cost_field(finder.costs(view), view.cell, view.grid.resolution_m)
    return finder.find(view, paths, max_candidates=max_candidates)


class GoalFinder:
    """Candidate goals for one episode, with the memory and caches that make them cheap.

    Memory (``[row, col]`` grids, written by the agent through the methods below): ``bumps``
    (contact regions), ``failed_until`` and ``unreachable_until`` (step until which a cell is
    no goal), ``times_tried``, ``times_blacklisted``.
    """

    def __init__(self, settings: CandidateSettings | None = None) -> None:
        self.settings = settings or CandidateSettings()

    # -- episode -----------------------------------------------------------------------------
    def reset(self, view: RobotView) -> None:
        """Forget everything: a new episode starts from ``view``."""
        grid = view.grid
        shape, res = grid.shape, grid.resolution_m
        self.bumps = np.zeros(shape, bool)
        self.failed_until = np.zeros(shape, np.int64)
        self.unreachable_until = np.zeros(shape, np.int64)
        self.times_tried = np.zeros(shape, np.int32)
        self.times_blacklisted = np.zeros(shape, np.int32)
        # A goal cell resolves a target when the robot stops within the follower's tolerance of
        # its centre and the target's centre is within the robot's radius of the robot's centre.
        self.goal_tolerance_m = 0.6 * res
        self.reach_offsets = disk_offsets(max((view.radius_m - self.goal_tolerance_m) / res, 0.5))
        self._near_offsets = disk_offsets(self.settings.near_radius_m / res)
        xs, ys = grid.cell_centres()
        self._col_x, self._row_y = xs[0], ys[:, 0]  # cell centres: x by column, y by row
        self._belief = np.array(view.belief_u8, np.uint8)
        self._frontier = frontier_mask(self._belief)
        self._wall_terms: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        self._near_bump = np.zeros(shape, bool)
        self._heard = np.full(shape, float(NOT_HEARD_DBM))
        self._n_heard = 0
        self._zone: np.ndarray | None = None
        self._zone_step = -(10**9)
        self.step = 0

    def set_step(self, step: int) -> None:
        """The agent's step count (the clock of the ``*_until`` memories)."""
        self.step = int(step)

    # -- memory ------------------------------------------------------------------------------
    def mark_bump(self, view: RobotView) -> None:
        """Remember a wall where the bumper fired."""
        mark_contact(self.bumps, view.grid, view.odometry_pose, view.radius_m)
        res = view.grid.resolution_m
        self._near_bump = ndimage.binary_dilation(
            self.bumps, iterations=max(1, round(self.settings.bump_exclusion_m / res))
        )

    def note_tried(self, target: tuple[int, int], radius_cells: float) -> None:
        """Count a goal chosen at ``target`` (for ``times_tried``)."""
        self.times_tried[disk_cells(self.times_tried.shape, target, radius_cells)] += 1

    def blacklist(self, target: tuple[int, int], radius_cells: float, until_step: int) -> None:
        """No goal within ``radius_cells`` of ``target`` until ``until_step``."""
        cells = disk_cells(self.failed_until.shape, target, radius_cells)
        self.failed_until[cells] = np.maximum(self.failed_until[cells], until_step)
        self.times_blacklisted[cells] += 1

    def mark_unreachable(self, cells: np.ndarray, until_step: int) -> None:
        """The ``(N, 2)`` cells are walled off on the map: no goals until ``until_step``."""
        self.unreachable_until[cells[:, 0], cells[:, 1]] = until_step

    @property
    def failed(self) -> np.ndarray:
        """Cells near a goal given up, now."""
        return self.failed_until > self.step

    @property
    def unreachable(self) -> np.ndarray:
        """Frontier cells found walled off, now."""
        return self.unreachable_until > self.step

    # -- map analysis ------------------------------------------------------------------------
    def frontier(self, view: RobotView) -> np.ndarray:
        """Frontier cells of ``view``'s belief (read-only; updated where the belief changed)."""
        changed = np.flatnonzero(self._belief.ravel() != view.belief_u8.ravel())
        if len(changed):
            update_frontier(view.belief_u8, self._belief, changed, self._frontier)
        return self._frontier

    def costs(self, view: RobotView, escape_wall_cost: float | None = None) -> np.ndarray:
        """Planner costs with the robot's cell passable. With ``escape_wall_cost``, believed walls
        cost that much per cell (bumps 4×) instead of blocking: the map's walls are doubted."""
        walls = view.belief_u8 <= U8_WALL_MAX
        res, radius = view.grid.resolution_m, view.radius_m
        unknown_cost = float(self.settings.unknown_cost)
        if escape_wall_cost is None:  # traversal_costs with walls and bumps blocking
            term = self._wall_term("blocking", walls | self.bumps, res, radius)
            r, c = view.cell
            return _known_wall_costs(view.belief_u8, term, unknown_cost, int(r), int(c))
        # traversal_costs of the belief's walls, which then cost instead of blocking
        unknown = ~walls & (view.belief_u8 < U8_FREE_MIN)
        cost = np.where(unknown, unknown_cost, 1.0) + self._wall_term("doubted", walls, res, radius)
        cost[walls] = escape_wall_cost
        cost[self.bumps] = 4 * escape_wall_cost
        return free_start(cost, view.cell)

    def _wall_term(self, name: str, walls: np.ndarray, res: float, radius: float) -> np.ndarray:
        """:func:`wall_cost_term` of ``walls``, kept per ``name`` and updated only around the
        cells that changed since the last call (one distance transform when many did)."""
        seen, term = self._wall_terms.get(name, (np.zeros_like(walls), np.zeros(walls.shape)))
        changed = np.flatnonzero(walls != seen)
        band = WallBand(radius)
        if len(changed) > walls.size // 20:
            term = (
                wall_cost_term(wall_distance_m(walls, res), res, band)
                if walls.any()
                else np.zeros(walls.shape)
            )
        elif len(changed):
            update_wall_cost_term(term, walls, changed, res, band)
        self._wall_terms[name] = (walls, term)
        return term

    def approach(self, paths: CostField) -> np.ndarray:
        """Per cell: the cheapest path cost to a cell whose footprint covers it."""
        cum = paths.cumulative
        h, w = cum.shape
        out = np.full_like(cum, np.inf)
        for dr, dc in self.reach_offsets:
            src = cum[max(dr, 0) : h + min(dr, 0), max(dc, 0) : w + min(dc, 0)]
            dst = out[max(-dr, 0) : h + min(-dr, 0), max(-dc, 0) : w + min(-dc, 0)]
            np.minimum(dst, src, out=dst)
        return out

    def approach_cell(self, paths: CostField, target: tuple[int, int]) -> tuple[int, int]:
        """The cheapest reachable cell whose footprint covers ``target`` (``target`` if none)."""
        r, c = self.approach_cells(paths, np.asarray([target]))[0]
        return int(r), int(c)

    def approach_at(self, paths: CostField, targets: np.ndarray) -> np.ndarray:
        """:meth:`approach` at ``targets`` ``(N, 2)`` only."""
        cells = np.asarray(targets, np.int64).reshape(-1, 2)
        return min_over_offsets(paths.cumulative, cells, self.reach_offsets)[0]

    def approach_cells(self, paths: CostField, targets: np.ndarray) -> np.ndarray:
        """:meth:`approach_cell` of each of ``targets`` ``(N, 2)`` (the target where none is
        reachable)."""
        return self._approach(paths, targets)[1]

    def _approach(self, paths: CostField, targets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`approach_at` and :meth:`approach_cells` of ``targets`` in one pass."""
        cells = np.asarray(targets, np.int64).reshape(-1, 2)
        cost, best = min_over_offsets(paths.cumulative, cells, self.reach_offsets)
        out = cells + self.reach_offsets[best]
        out[~np.isfinite(cost)] = cells[~np.isfinite(cost)]
        return cost, out

    def heading_change(self, view: RobotView, cells: np.ndarray) -> np.ndarray:
        """The absolute angle between the bearing from the robot to each cell and its heading,
        radians in [0, π]."""
        x, y, th = view.odometry_pose
        bearing = np.arctan2(self._row_y[cells[:, 0]] - y, self._col_x[cells[:, 1]] - x) - th
        return np.abs(wrap_angle(bearing))

    def exclusion(self, view: RobotView) -> np.ndarray:
        """Cells that are no frontier goals: near a bump (walls), failed or walled off, or in a
        small unknown pocket inside known space (it will be resolved in passing)."""
        exclude = self._near_bump | self.failed | self.unreachable
        min_area = self.settings.min_unknown_region_m2
        if min_area > 0:
            res = view.grid.resolution_m
            _, _, unknown = belief_classes(view.belief_u8)
            labels, n = ndimage.label(unknown, structure=EIGHT_CONNECTED)
            if n:
                area = np.bincount(labels.ravel(), minlength=n + 1) * res * res
                area[0] = np.inf
                exclude |= area[labels] < min_area
        return exclude

    def excluded_at(self, view: RobotView, flat: np.ndarray) -> np.ndarray:
        """:meth:`exclusion` at the cells ``flat`` (flat indices) only: the pockets are flood-filled
        from those cells alone (bounded fills, much cheaper than labelling the whole map)."""
        return excluded_cells(
            np.ascontiguousarray(view.belief_u8),
            np.asarray(flat, np.int64),
            self._near_bump,
            self.failed_until,
            self.unreachable_until,
            self.step,
            self._pocket_cells(view.grid.resolution_m),
        )

    def _pocket_cells(self, resolution_m: float) -> int:
        """The fewest cells of an unknown region that is no pocket (0: no pockets excluded)."""
        min_area = self.settings.min_unknown_region_m2
        if min_area <= 0:
            return 0
        n_big = int(np.ceil(min_area / resolution_m**2 - 1e-9))
        while n_big * resolution_m * resolution_m < min_area:
            n_big += 1
        return n_big

    def strongest_router(self, view: RobotView) -> np.ndarray:
        """Per cell, the router predicted strongest there (refit every ``zones_every_steps``)."""
        if self._zone is None or self.step - self._zone_step >= self.settings.zones_every_steps:
            traj, hist = view.odometry_trajectory, view.rssi_history
            n = min(len(traj), len(hist))
            scores = router_scores(view.grid, view.routers_xy, traj[-n:], hist[-n:])
            self._zone = np.argmax(scores, axis=0)
            self._zone_step = self.step
        return self._zone

    def expected_gain(self, view: RobotView, cells: np.ndarray) -> np.ndarray:
        """Bits the mapper would gain with the robot at each of ``cells`` ``(N, 2)``: the entropy
        of the unknown cells on the ray from the router predicted strongest there, plus that of
        the unknown cells in the robot's footprint."""
        grid = view.grid
        routers = np.asarray(view.routers_xy, np.float64)
        zone = self.strongest_router(view)
        ends = grid.cell_to_world(cells)
        starts = routers[zone[cells[:, 0], cells[:, 1]]]
        length = np.linalg.norm(ends - starts, axis=1)
        n = max(2, int(np.ceil(length.max(initial=0.0) / (0.5 * grid.resolution_m))) + 1)
        return _expected_gain(
            view.log_odds,
            view.belief_u8,
            starts,
            ends,
            np.linspace(0.0, 1.0, n),
            np.asarray(grid.origin_xy, np.float64),
            float(grid.resolution_m),
            np.asarray(cells, np.int64),
            self.reach_offsets,
        )

    def _disk_sum(self, values: np.ndarray, cells: np.ndarray, offsets: np.ndarray) -> np.ndarray:
        """Per cell, the sum of ``values`` over ``cells + offsets`` inside the grid."""
        h, w = values.shape
        r = cells[:, None, 0] + offsets[None, :, 0]
        c = cells[:, None, 1] + offsets[None, :, 1]
        inside = (r >= 0) & (r < h) & (c >= 0) & (c < w)
        return (values[r.clip(0, h - 1), c.clip(0, w - 1)] * inside).sum(axis=1)

    def _strongest_heard_near(self, view: RobotView, cells: np.ndarray) -> np.ndarray:
        """The strongest RSSI heard within ``near_radius_m`` of each cell (dBm)."""
        traj, hist = view.odometry_trajectory, view.rssi_history
        n = min(len(traj), len(hist))
        if n > self._n_heard:  # fold in the readings since the last call
            rc = view.grid.world_to_cell(traj[self._n_heard : n])
            h, w = self._heard.shape
            ok = (rc[:, 0] >= 0) & (rc[:, 0] < h) & (rc[:, 1] >= 0) & (rc[:, 1] < w)
            strongest = hist[self._n_heard : n].max(axis=1, initial=NOT_HEARD_DBM)
            np.maximum.at(self._heard, (rc[ok, 0], rc[ok, 1]), strongest[ok])
            self._n_heard = n
        h, w = self._heard.shape
        r = cells[:, None, 0] + self._near_offsets[None, :, 0]
        c = cells[:, None, 1] + self._near_offsets[None, :, 1]
        inside = (r >= 0) & (r < h) & (c >= 0) & (c < w)
        near = np.where(inside, self._heard[r.clip(0, h - 1), c.clip(0, w - 1)], NOT_HEARD_DBM)
        return near.max(axis=1, initial=float(NOT_HEARD_DBM))

    # -- the menu ----------------------------------------------------------------------------
    def find(
        self,
        view: RobotView,
        paths: CostField,
        *,
        max_candidates: int | None = None,
        sources: tuple[str, ...] = SOURCES,
        features: tuple[str, ...] = FEATURES,
        anchor_rc: tuple[int, int] | None = None,
        anchor_cost_per_m: float = 0.0,
    ) -> CandidateGoals:
        """The candidates of ``sources`` for ``view`` on ``paths``: all of them with
        ``max_candidates=None``, else the quotas of :func:`candidate_goals`. Only the columns
        named in ``features`` are computed (the others are NaN): agents ask for what they use.

        With ``anchor_rc``, a frontier cluster's target is its cheapest cell counting also
        ``anchor_cost_per_m`` (path metres) per metre between the cell and the anchor."""
        _check_names(tuple(sources), tuple(features))
        res = view.grid.resolution_m
        frontier = self.frontier(view)
        x, y, heading = view.odometry_pose
        open_cells, open_cost, members, bounds, best = frontier_menu(
            np.ascontiguousarray(view.belief_u8),
            np.flatnonzero(frontier),
            self._near_bump,
            self.failed_until,
            self.unreachable_until,
            self.step,
            self._pocket_cells(res),
            paths.cumulative,
            self.reach_offsets,
            self._row_y,
            self._col_x,
            float(x),
            float(y),
            float(heading),
            float(self.settings.turn_cost_m_per_rad),
            max(1, round(self.settings.min_frontier_size_m / res)),
            -1 if anchor_rc is None else int(anchor_rc[0]),
            -1 if anchor_rc is None else int(anchor_rc[1]),
            float(anchor_cost_per_m),
        )
        reachable = np.isfinite(open_cost)
        walled_off_rc = open_cells[~reachable]
        targets: list[np.ndarray] = []
        source: list[np.ndarray] = []
        sizes: list[np.ndarray] = []
        clusters = _Clusters(np.zeros((0, 2), np.int64), np.zeros(1, np.int64), 0)
        for name in sources:
            if name == "frontier":
                every = np.stack(np.divmod(members, frontier.shape[1]), axis=1)
                cells, size = every[best], np.diff(bounds).astype(np.float64)
                clusters = _Clusters(every, bounds, sum(len(t) for t in targets))
            elif name == "hidden_room":
                cells, size, _ = self.hidden_room_targets(view)
            else:
                cells = open_cells[reachable]
                k = self.settings.info_gain_samples
                if len(cells) > k:
                    cells = cells[np.linspace(0, len(cells) - 1, k).astype(int)]
                size = np.zeros(len(cells))
            targets.append(cells.reshape(-1, 2))
            source.append(np.full(len(cells), SOURCES.index(name), np.int64))
            sizes.append(size)
        if len(targets) == 1:
            target_rc, src, size_m = targets[0].astype(np.int64), source[0], sizes[0] * res
        else:
            target_rc = np.concatenate([np.zeros((0, 2), np.int64), *targets]).astype(np.int64)
            src = np.concatenate([np.zeros(0, np.int64), *source])
            size_m = np.concatenate([np.zeros(0), *sizes]) * res
        path_cost, goal_rc = self._approach(paths, target_rc)
        gain = np.full(len(target_rc), np.nan)
        info = src == SOURCES.index("info_gain")
        if info.any() and (max_candidates is not None or "expected_gain_bits" in features):
            gain[info] = self.expected_gain(view, target_rc[info])
        if max_candidates is not None:
            keep = _select(src, path_cost, size_m, gain, max_candidates)
            target_rc, src, path_cost, size_m, gain = (
                target_rc[keep],
                src[keep],
                path_cost[keep],
                size_m[keep],
                gain[keep],
            )
            goal_rc = goal_rc[keep]
            clusters = clusters.taken(keep)
        feats = np.full((len(target_rc), len(FEATURES)), np.nan)
        if len(target_rc):
            for name in features:
                feats[:, _F[name]] = self._feature(
                    name, view, target_rc, src, path_cost, size_m, gain
                )
        return CandidateGoals(
            target_rc,
            goal_rc,
            src,
            feats,
            np.isfinite(path_cost),
            clusters.padded(len(target_rc)),
            paths,
            walled_off_rc,
        )

    def _feature(
        self,
        name: str,
        view: RobotView,
        target_rc: np.ndarray,
        src: np.ndarray,
        path_cost: np.ndarray,
        size_m: np.ndarray,
        gain: np.ndarray,
    ) -> np.ndarray:
        """The :data:`FEATURES` column ``name`` of the menu's candidates."""
        r, c = target_rc[:, 0], target_rc[:, 1]
        if name == "path_cost_m":
            return path_cost
        if name == "heading_change_rad":
            return self.heading_change(view, target_rc)
        if name == "cluster_size_m":
            return size_m
        if name == "distance_m":
            return np.linalg.norm(view.grid.cell_to_world(target_rc) - view.xy, axis=1)
        if name == "expected_gain_bits":
            return _fill(gain, lambda m: self.expected_gain(view, target_rc[m]))
        if name == "unknown_area_m2":
            unknown = belief_classes(view.belief_u8)[2].astype(np.float64)
            res = view.grid.resolution_m
            return self._disk_sum(unknown, target_rc, self._near_offsets) * res**2
        if name == "times_tried":
            return self.times_tried[r, c]
        if name == "times_blacklisted":
            return self.times_blacklisted[r, c]
        if name == "is_hidden_room":
            return src == SOURCES.index("hidden_room")
        assert name == "strongest_rssi_dbm", name
        return self._strongest_heard_near(view, target_rc)

    def hidden_room_targets(
        self, view: RobotView
    ) -> tuple[np.ndarray, np.ndarray, list[np.ndarray]]:
        """The deepest cell of each hidden room that has not failed as a goal."""
        min_depth = max(self.settings.min_hidden_room_depth_m / view.grid.resolution_m, 1.0)
        depth = np.where(self.failed, 0.0, hidden_rooms(view.belief_u8, min_depth))
        if not depth.any():
            return np.zeros((0, 2), np.int64), np.zeros(0), []
        labels, n = ndimage.label(depth > 0, structure=EIGHT_CONNECTED)
        deepest = np.array(ndimage.maximum_position(depth, labels, range(1, n + 1)), np.int64)
        return deepest.reshape(-1, 2), np.zeros(len(deepest)), []


@functools.cache
def _check_names(sources: tuple[str, ...], features: tuple[str, ...]) -> None:
    """Refuse unknown source or feature names (checked once per pair of tuples)."""
    for given, known in ((sources, SOURCES), (features, FEATURES)):
        unknown_names = set(given) - set(known)
        if unknown_names:
            raise ValueError(f"unknown names {sorted(unknown_names)}; known: {known}")


class _Clusters(Sequence[np.ndarray]):
    """A menu's per-candidate frontier clusters, sliced from one array when asked: candidate
    ``i`` has cluster ``i - first`` of ``cells`` (grouped by ``bounds``), or none (empty)."""

    def __init__(
        self, cells: np.ndarray, bounds: np.ndarray, first: int, size: int | None = None
    ) -> None:
        self._cells, self._bounds, self._first = cells, bounds, first
        self._index: np.ndarray | None = None  # candidate -> cluster (-1: none), once selected
        self._size = first + len(bounds) - 1 if size is None else size

    def taken(self, keep: np.ndarray) -> _Clusters:
        """The clusters of the candidates ``keep`` (in that order)."""
        out = _Clusters(self._cells, self._bounds, 0, len(keep))
        k = np.asarray(keep, np.int64) - self._first
        n = len(self._bounds) - 1
        out._index = np.where((k >= 0) & (k < n), k, -1)
        return out

    def padded(self, size: int) -> _Clusters:
        """The same clusters in a menu of ``size`` candidates (those past the frontier's have
        none)."""
        self._size = size
        return self

    def __len__(self) -> int:
        return self._size

    def __getitem__(self, i):
        if isinstance(i, slice):
            return tuple(self[j] for j in range(*i.indices(len(self))))
        if not -self._size <= i < self._size:
            raise IndexError(i)
        i = int(i) % self._size
        k = i - self._first if self._index is None else int(self._index[i])
        if not 0 <= k < len(self._bounds) - 1:
            return np.zeros((0, 2), np.int64)
        return self._cells[self._bounds[k] : self._bounds[k + 1]]


def _select(
    source: np.ndarray, path_cost: np.ndarray, size_m: np.ndarray, gain: np.ndarray, k: int
) -> np.ndarray:
    """Indices of at most ``k`` candidates by the quotas of :func:`candidate_goals` (valid
    ones first; in their original order)."""
    quotas = {"frontier": k - k // 4, "hidden_room": max(1, k // 8), "info_gain": k}
    valid = np.isfinite(path_cost)
    rank = {
        "frontier": -(size_m - 3.0 * path_cost),
        "hidden_room": path_cost,
        "info_gain": -gain / (path_cost + 1.0),
    }
    chosen: list[int] = []
    spare: list[int] = []
    for name in SOURCES:
        idx = np.flatnonzero(source == SOURCES.index(name))
        order = idx[np.lexsort((idx, np.nan_to_num(rank[name][idx], nan=np.inf), ~valid[idx]))]
        take = min(quotas[name], k - len(chosen))
        chosen += order[:take].tolist()
        spare += order[take:].tolist()
    spare.sort(key=lambda i: (not valid[i], source[i], i))
    chosen += spare[: k - len(chosen)]
    return np.array(sorted(chosen), np.int64)


def _fill(values: np.ndarray, compute) -> np.ndarray:
    """``values`` with its NaN entries replaced by ``compute(mask_of_nans)``."""
    missing = np.isnan(values)
    if missing.any():
        values = values.copy()
        values[missing] = compute(missing)
    return values


@njit(cache=True)
def unknown_bits_at(log_odds, belief, r, c):  # pragma: no cover (compiled)
    """Entropy (bits) of cell (r, c) if the belief there is unknown, else 0."""
    b = belief[r, c]
    if b <= U8_WALL_MAX or b >= U8_FREE_MIN:
        return 0.0
    return cell_entropy_bits(np.float64(log_odds[r, c]))


@njit(cache=True)
def footprint_bits(log_odds, belief, r0, c0, footprint, seen, mark):  # pragma: no cover
    """The unknown bits of the cells ``(r0, c0) + footprint`` inside the grid, each once: a
    cell is counted where ``seen`` does not hold ``mark`` yet (and is marked)."""
    h, w = belief.shape
    total = 0.0
    for k in range(len(footprint)):
        r, c = r0 + footprint[k, 0], c0 + footprint[k, 1]
        if 0 <= r < h and 0 <= c < w and seen[r, c] != mark:
            seen[r, c] = mark
            total += unknown_bits_at(log_odds, belief, r, c)
    return total


@njit(cache=True)
def ray_cells(r0, c0, target, radius, origin, res, blocked, buf):  # pragma: no cover (compiled)
    """``(K, 2)`` cells of the ray from cell (r0, c0)'s centre towards the point ``target``,
    sampled every half cell, from beyond ``radius`` (m; the robot's footprint) to the target,
    the grid's edge or the first cell where ``blocked`` (bool, the grid's shape) holds (not
    included; a cell repeats where several samples fall in it), and whether it reached the
    target. The cells are a view of ``buf`` ``(M, 2)`` when it is long
    enough (kernels that walk many rays pass one, :func:`ray_buffer`), valid until the next
    call with it."""
    h, w = blocked.shape
    x0 = origin[0] + (c0 + 0.5) * res
    y0 = origin[1] + (r0 + 0.5) * res
    dx, dy = target[0] - x0, target[1] - y0
    length = np.hypot(dx, dy)
    n = int(np.ceil(length / (0.5 * res)))
    out = buf if len(buf) >= n else np.empty((n, 2), np.int64)
    k = 0
    for j in range(1, n + 1):
        t = j / n
        if t * length <= radius:
            continue
        r = int(np.floor((y0 + dy * t - origin[1]) / res))
        c = int(np.floor((x0 + dx * t - origin[0]) / res))
        if not (0 <= r < h and 0 <= c < w) or blocked[r, c]:
            return out[:k], False
        out[k, 0], out[k, 1] = r, c
        k += 1
    return out[:k], True


@njit(cache=True)
def ray_buffer(shape):  # pragma: no cover (compiled)
    """A buffer for :func:`ray_cells` long enough for any ray between two points of a grid of
    ``shape`` (samples every half cell along its diagonal)."""
    return np.empty((int(2 * np.hypot(shape[0], shape[1])) + 4, 2), np.int64)


@njit(cache=True)
def _expected_gain(
    log_odds, belief, starts, ends, t, origin, res, cells, offsets
):  # pragma: no cover (compiled)
    """Per candidate i: the entropy of the unknown cells on the segment ``starts[i]`` →
    ``ends[i]`` (sampled at ``t``; each cell once) plus that of the unknown cells at
    ``cells[i] + offsets`` inside the grid."""
    h, w = belief.shape
    out = np.zeros(len(cells))
    for i in range(len(cells)):
        total = 0.0
        last_r, last_c = -1, -1
        for j in range(len(t)):
            x = starts[i, 0] + (ends[i, 0] - starts[i, 0]) * t[j]
            y = starts[i, 1] + (ends[i, 1] - starts[i, 1]) * t[j]
            r = min(max(int(np.floor((y - origin[1]) / res)), 0), h - 1)
            c = min(max(int(np.floor((x - origin[0]) / res)), 0), w - 1)
            if r != last_r or c != last_c:  # a segment meets each cell in one run of samples
                total += unknown_bits_at(log_odds, belief, r, c)
                last_r, last_c = r, c
        for k in range(len(offsets)):
            r, c = cells[i, 0] + offsets[k, 0], cells[i, 1] + offsets[k, 1]
            if 0 <= r < h and 0 <= c < w:
                total += unknown_bits_at(log_odds, belief, r, c)
        out[i] = total
    return out


@njit(cache=True)
def _known_wall_costs(belief, wall_term, unknown_cost, r0, c0):  # pragma: no cover (compiled)
    """``free_start(where(unknown, unknown_cost, 1) + wall_term, (r0, c0))`` in one pass."""
    h, w = belief.shape
    out = np.empty((h, w))
    for r in range(h):
        for c in range(w):
            unknown = U8_WALL_MAX < belief[r, c] < U8_FREE_MIN
            out[r, c] = (unknown_cost if unknown else 1.0) + wall_term[r, c]
    for r in range(max(r0 - 1, 0), min(r0 + 2, h)):
        for c in range(max(c0 - 1, 0), min(c0 + 2, w)):
            if not np.isfinite(out[r, c]):
                out[r, c] = FREE_START_COST
    return out
