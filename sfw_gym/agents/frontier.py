"""Frontier exploration (Yamauchi 1997) in explore_lite's form, adapted to an RSSI-built map.

A frontier is an unknown cell next to a believed-free cell of the thresholded belief; frontier
cells are grouped into 8-connected clusters (:func:`scipy.ndimage.label`). Each cluster reachable
on the belief map gets the utility ``gain_scale · size_m − potential_scale · path_m`` (explore_lite),
where ``path_m`` is the cost-weighted path distance from the robot to the cluster's nearest cell;
the best cluster's nearest cell is the goal.

What differs from a LiDAR map. The map fills where the rays router→robot sweep, not around the
robot, so (1) unknown space is everywhere, also behind the robot, and the frontier is long and
fragmented; (2) the robot's own footprint leaves a thin unknown fringe along its path that no ray
may ever fill (the cells just beyond its radius, and walls it has touched): frontier cells within
``visited_margin_m`` of the robot's own path are not goals (standing there did not resolve them,
so they are walls or beyond reach); (3) reaching a frontier resolves little by itself, so a goal
is pushed ``goal_depth_m`` into the unknown behind it, which lays new trajectory anchors for the
mapper's rays to join. A goal that makes no progress for ``progress_timeout_steps`` steps, or that
the planner cannot reach, is blacklisted; a bump replans. When no frontier is left (or all are
blacklisted) the agent records why in ``stop_reason`` and keeps sweeping: it drives to the
reachable cell farthest from its path so far, so that an episode never stalls while unknown space
is left.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import ndimage

from sfw_gym.agents.base import Agent, RobotView, check_fraction
from sfw_gym.agents.planning import (
    CostField,
    PurePursuit,
    belief_classes,
    cost_field,
    free_start,
    simplify_path,
    traversal_costs,
)
from sfw_gym.errors import ConfigError

_EIGHT = np.ones((3, 3), bool)


@dataclass(frozen=True)
class Frontier:
    """One frontier cluster.

    Attributes:
        cells: ``(N, 2)`` cells ``(row, col)``.
        centroid_rc: Mean cell, ``(row, col)`` floats.
    """

    cells: np.ndarray
    centroid_rc: tuple[float, float]

    @property
    def size(self) -> int:
        """Number of cells."""
        return len(self.cells)


def frontier_mask(belief_u8: np.ndarray, exclude: np.ndarray | None = None) -> np.ndarray:
    """Unknown cells 8-adjacent to a believed-free cell (optionally minus ``exclude``)."""
    free, _, unknown = belief_classes(belief_u8)
    mask = unknown & ndimage.binary_dilation(free, structure=_EIGHT)
    if exclude is not None:
        mask &= ~exclude
    return mask


def find_frontiers(
    belief_u8: np.ndarray, min_size_cells: int = 1, exclude: np.ndarray | None = None
) -> list[Frontier]:
    """Frontier clusters of a belief map (0 wall, 255 free, 127 unknown), largest first.

    Args:
        belief_u8: The belief, ``[row, col]``.
        min_size_cells: Clusters smaller than this are dropped.
        exclude: Optional mask of cells that are never frontier cells.

    Returns:
        The clusters (8-connected), sorted by decreasing size.
    """
    mask = frontier_mask(belief_u8, exclude)
    labels, n = ndimage.label(mask, structure=_EIGHT)
    if n == 0:
        return []
    rows, cols = np.nonzero(labels)
    lab = labels[rows, cols]
    order = np.argsort(lab, kind="stable")
    rows, cols, lab = rows[order], cols[order], lab[order]
    bounds = np.searchsorted(lab, np.arange(1, n + 2))
    out = []
    for i in range(n):
        a, b = bounds[i], bounds[i + 1]
        if b - a < min_size_cells:
            continue
        cells = np.stack([rows[a:b], cols[a:b]], axis=1)
        out.append(Frontier(cells, (float(rows[a:b].mean()), float(cols[a:b].mean()))))
    out.sort(key=lambda f: -f.size)
    return out


@dataclass
class Goal:
    """The goal being pursued: its cell, what it is for, and its progress bookkeeping."""

    cell: tuple[int, int]
    kind: str  # "frontier" | "sweep" | a subclass's own kind
    best_remaining_m: float = np.inf
    steps_without_progress: int = 0
    final_xy: np.ndarray | None = None  # where to drive after reaching the cell (a straight pass)


class FrontierAgent(Agent):
    """Frontier exploration with explore_lite's utility, a grid planner and pure pursuit.

    Args:
        gain_scale: Weight of a cluster's size (metres of frontier) in its utility.
        potential_scale: Weight of the path distance (metres) to it.
        min_frontier_size_m: Clusters shorter than this (cells × resolution) are ignored.
        progress_timeout_steps: Steps without getting 5 cm closer to a goal before it is
            blacklisted.
        blacklist_radius_m: A cluster whose goal lies this close to a blacklisted goal is skipped.
        replan_every_steps: Re-pick the goal this often, as the map changes under the robot.
        unknown_cost: Planner cost of an unknown cell (a free one costs 1).
        goal_depth_m: How far past the frontier cell into the unknown the robot aims.
        visited_margin_m: Frontier cells within radius + this of the robot's path are not goals.
        lookahead_m: Pure-pursuit carrot distance.
        backoff_steps: Steps of reversing after a bump (continuous actions only).
        bump_exclusion_m: Frontier cells this close to a bump are not goals (walls).
        min_unknown_depth_m: A frontier must open onto unknown space at least this deep
            (thinner strips between known regions are unresolved walls).
        max_steps: Optional step limit of the agent (``stop_reason = "max_steps"``).
    """

    name = "frontier"

    def __init__(
        self,
        gain_scale: float = 1.0,
        potential_scale: float = 3.0,
        min_frontier_size_m: float = 0.5,
        progress_timeout_steps: int = 40,
        blacklist_radius_m: float = 0.5,
        replan_every_steps: int = 10,
        unknown_cost: float = 1.5,
        goal_depth_m: float = 1.0,
        visited_margin_m: float = 0.15,
        lookahead_m: float = 0.5,
        backoff_steps: int = 1,
        bump_exclusion_m: float = 0.4,
        min_unknown_depth_m: float = 0.3,
        max_steps: int | None = None,
    ) -> None:
        super().__init__(max_steps=max_steps)
        self.gain_scale = check_fraction("gain_scale", gain_scale)
        self.potential_scale = check_fraction("potential_scale", potential_scale)
        self.min_frontier_size_m = check_fraction("min_frontier_size_m", min_frontier_size_m)
        self.blacklist_radius_m = check_fraction("blacklist_radius_m", blacklist_radius_m)
        self.unknown_cost = check_fraction("unknown_cost", unknown_cost, 1.0)
        self.goal_depth_m = check_fraction("goal_depth_m", goal_depth_m)
        self.visited_margin_m = check_fraction("visited_margin_m", visited_margin_m)
        self.lookahead_m = check_fraction("lookahead_m", lookahead_m, 0.05)
        for name, v, lo in (("progress_timeout_steps", progress_timeout_steps, 1),
                            ("replan_every_steps", replan_every_steps, 1),
                            ("backoff_steps", backoff_steps, 0)):  # fmt: skip
            if isinstance(v, bool) or not isinstance(v, int) or v < lo:
                raise ConfigError(f"{name} must be an int >= {lo}, got {v!r}")
        self.backoff_steps = backoff_steps
        self.bump_exclusion_m = check_fraction("bump_exclusion_m", bump_exclusion_m)
        self.min_unknown_depth_m = check_fraction("min_unknown_depth_m", min_unknown_depth_m)
        self.progress_timeout_steps = progress_timeout_steps
        self.replan_every_steps = replan_every_steps

    # -- episode ---------------------------------------------------------------------------------
    def _on_reset(self, view: RobotView) -> None:
        res = view.grid.resolution_m
        self.blacklisted = np.zeros(view.grid.shape, bool)
        self.bumps = np.zeros(view.grid.shape, bool)
        self._blacklist_radius_cells = self.blacklist_radius_m / res
        self._bump_radius_cells = max(1.0, 0.1 / res)
        self.goal: Goal | None = None
        self.follower = PurePursuit(lookahead_m=self.lookahead_m)
        self.visited = np.zeros(view.grid.shape, bool)
        self._visit_radius_cells = (view.radius_m + self.visited_margin_m) / res
        self._since_plan = 0
        self._backoff = 0
        self.n_blacklisted = 0
        self.n_goals = 0

    def _act(self, view: RobotView, obs: Any) -> tuple[float, float]:
        self._mark_visited(view)
        pose = view.odometry_pose
        # A bump while driving forward: remember the wall ahead, back off (continuous) and
        # replan. Contact while turning or reversing says nothing about what lies ahead.
        bumped_ahead = view.bumped and self.last_command[0] > 0
        if bumped_ahead:
            self._mark_bump(view)
            if self.action_type == "continuous":
                self._backoff = self.backoff_steps
        if self._backoff > 0:
            self._backoff -= 1
            self.goal = None if self._backoff == 0 else self.goal
            return -1.0, 0.0
        goal = self.goal
        replan = goal is None or bumped_ahead or self._since_plan >= self.replan_every_steps
        if goal is not None and not replan:
            remaining = self.follower.remaining_m(view.xy)
            if not self.follower.has_path:
                if goal.final_xy is not None:  # a straight pass after the goal cell
                    self.follower.set_path(np.stack([view.xy, goal.final_xy]))
                    goal.final_xy = None
                    goal.best_remaining_m = np.inf
                else:
                    replan = True
            elif remaining < goal.best_remaining_m - 0.05:
                goal.best_remaining_m = remaining
                goal.steps_without_progress = 0
            else:
                goal.steps_without_progress += 1
                if goal.steps_without_progress >= self.progress_timeout_steps:
                    self._blacklist(goal)
                    replan = True
        if replan:
            self._plan(view)
        self._since_plan += 1
        if not self.follower.has_path:  # nothing to drive to: turn in place, never stand still
            return 0.0, 1.0
        return self.follower.command(pose)

    # -- goals -----------------------------------------------------------------------------------
    def _mark_visited(self, view: RobotView) -> None:
        self._mark_disk(self.visited, view.cell, self._visit_radius_cells)

    def _blacklist(self, goal: Goal) -> None:
        """Blacklist the cells within ``blacklist_radius_m`` of a goal."""
        self._mark_disk(self.blacklisted, goal.cell, self._blacklist_radius_cells)
        self.n_blacklisted += 1
        self.goal = None

    @staticmethod
    def _mark_disk(mask: np.ndarray, cell: tuple[int, int], radius_cells: float) -> None:
        r, c = cell
        k = int(np.ceil(radius_cells))
        h, w = mask.shape
        r0, r1, c0, c1 = max(r - k, 0), min(r + k + 1, h), max(c - k, 0), min(c + k + 1, w)
        if r0 >= r1 or c0 >= c1:
            return
        rr, cc = np.ogrid[r0:r1, c0:c1]
        mask[r0:r1, c0:c1] |= (rr - r) ** 2 + (cc - c) ** 2 <= radius_cells * radius_cells

    def _mark_bump(self, view: RobotView) -> None:
        """Remember a wall where the bumper fired (the mapper marks one cell; walls are longer)."""
        x, y, th = view.odometry_pose
        reach = view.radius_m + view.grid.resolution_m
        contact = np.array([x + reach * np.cos(th), y + reach * np.sin(th)])
        cell = tuple(int(v) for v in view.grid.world_to_cell(contact))
        self._mark_disk(self.bumps, cell, self._bump_radius_cells)

    def _costs(self, view: RobotView) -> np.ndarray:
        cost = traversal_costs(
            view.belief_u8, view.grid.resolution_m, view.radius_m,
            unknown_cost=self.unknown_cost, blocked=self.bumps,
        )  # fmt: skip
        return free_start(cost, view.cell)

    def _plan(self, view: RobotView) -> None:
        """Pick a goal and a path to it (or fall back to sweeping)."""
        self._since_plan = 0
        field = cost_field(self._costs(view), view.cell, view.grid.resolution_m)
        candidate = self._choose_goal(view, field)
        if candidate is None:
            candidate = self._sweep_goal(view, field)
        self._set_goal(view, field, candidate)

    def _set_goal(self, view: RobotView, field: CostField, goal: Goal | None) -> None:
        if goal is None:
            self.goal = None
            self.follower.set_path(np.zeros((0, 2)))
            return
        prev = self.goal
        if prev is not None and prev.kind == goal.kind and prev.cell == goal.cell:
            goal.best_remaining_m = prev.best_remaining_m  # same goal: keep its progress clock
            goal.steps_without_progress = prev.steps_without_progress
        self.goal = goal
        self.n_goals += 1
        cells = field.path(goal.cell)
        xy = view.grid.cell_to_world(cells) if len(cells) else view.xy[None]
        self.follower.set_path(simplify_path(xy, 0.25))

    def _choose_goal(self, view: RobotView, field: CostField) -> Goal | None:
        res = view.grid.resolution_m
        frontiers = find_frontiers(
            view.belief_u8,
            max(1, int(round(self.min_frontier_size_m / res))),
            exclude=self._frontier_exclusion(view),
        )
        if not frontiers:
            self._stop("no_frontiers")
            return None
        best, best_u = None, -np.inf
        any_open = False
        for f in frontiers:
            dist = field.cumulative[f.cells[:, 0], f.cells[:, 1]]
            reachable = np.isfinite(dist)
            if not reachable.any():  # unreachable on the belief map: blacklist it
                self.blacklisted[f.cells[:, 0], f.cells[:, 1]] = True
                self.n_blacklisted += 1
                continue
            ok = reachable & ~self.blacklisted[f.cells[:, 0], f.cells[:, 1]]
            if not ok.any():
                continue
            any_open = True
            i = int(np.flatnonzero(ok)[np.argmin(dist[ok])])
            u = self._utility(view, f, float(dist[i]))
            if u > best_u:
                best, best_u = (f, i), u
        if not any_open or best is None:
            self._stop("all_blacklisted")
            return None
        f, i = best
        return Goal(self._deepen(view, field, tuple(f.cells[i]), f), "frontier")

    def _frontier_exclusion(self, view: RobotView) -> np.ndarray:
        """Cells that are not frontier goals: near the path, near bumps, or thin unknown strips.

        Unknown space only one or two cells deep between known regions is a wall the map has
        not resolved, not a way into unexplored space.
        """
        res = view.grid.resolution_m
        _, _, unknown = belief_classes(view.belief_u8)
        exclude = self.visited | ndimage.binary_dilation(
            self.bumps, iterations=max(1, int(round(self.bump_exclusion_m / res)))
        )
        if self.min_unknown_depth_m > 0:
            depth = ndimage.distance_transform_edt(unknown) * res
            window = 2 * int(round(self.min_unknown_depth_m / res)) + 3
            exclude |= ndimage.maximum_filter(depth, size=window) < self.min_unknown_depth_m
        return exclude

    def _utility(self, view: RobotView, f: Frontier, path_m: float) -> float:
        size_m = f.size * view.grid.resolution_m
        return self.gain_scale * size_m - self.potential_scale * path_m

    def _deepen(
        self, view: RobotView, field: CostField, cell: tuple[int, int], f: Frontier
    ) -> tuple[int, int]:
        """Push the goal ``goal_depth_m`` into unknown space, away from the robot."""
        if self.goal_depth_m <= 0:
            return cell
        res = view.grid.resolution_m
        here = np.array(view.cell, np.float64)
        d = np.array(cell, np.float64) - here
        n = np.linalg.norm(d)
        if n < 1e-9:
            return cell
        _, _, unknown = belief_classes(view.belief_u8)
        reach = field.reachable()
        best = cell
        h, w = unknown.shape
        for step in np.arange(1, int(self.goal_depth_m / res) + 1):
            rc = np.round(np.array(cell) + d / n * step).astype(int)
            if not (0 <= rc[0] < h and 0 <= rc[1] < w) or not reach[rc[0], rc[1]]:
                break
            if not unknown[rc[0], rc[1]]:
                break
            best = (int(rc[0]), int(rc[1]))
        return best

    def _sweep_goal(self, view: RobotView, field: CostField) -> Goal | None:
        """Fallback: the reachable cell farthest from the path so far (keeps the rays sweeping)."""
        reach = field.reachable() & np.isfinite(field.cumulative)
        free, _, unknown = belief_classes(view.belief_u8)
        target = reach & (free | unknown) & ~self.visited
        if not target.any():
            return None
        far = ndimage.distance_transform_edt(~self.visited)
        score = np.where(target, far, -1.0)
        if unknown[target].any():  # prefer unknown space
            score = np.where(target & unknown, far + 1e3, score)
        r, c = np.unravel_index(int(np.argmax(score)), score.shape)
        return Goal((int(r), int(c)), "sweep")
