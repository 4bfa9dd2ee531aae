"""Greedy information gain per metre: the reference 'next-best-view' agent for the RSSI mapper."""

from __future__ import annotations

from typing import Any

import numpy as np

from sfw_gym.agents.base import RobotView
from sfw_gym.agents.frontier import FrontierAgent, Goal
from sfw_gym.core.config import check
from sfw_gym.navigation.frontiers import frontier_mask
from sfw_gym.navigation.planning import CostField, belief_classes
from sfw_gym.navigation.radio_zones import router_scores


class GreedyInfoGainAgent(FrontierAgent):
    """Drive to the candidate goal with the most expected information gain per metre of path.

    Candidates are frontier cells (subsampled). A candidate's expected gain counts the unknown
    cells the mapper would update from there: those on the ray from the router predicted to be
    the strongest at the candidate (log-distance model with the robot's own RSSI residuals) to
    the candidate, plus the unknown cells in the robot's footprint there. The score is that count
    divided by the path distance plus ``distance_offset_m``. Motion, bumps, blacklisting and the
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

    def _on_reset(self, view: RobotView) -> None:
        super()._on_reset(view)
        self._zone: np.ndarray | None = None
        self._zones_at = -(10**9)

    def _strongest(self, view: RobotView) -> np.ndarray:
        if self._zone is None or self.steps - self._zones_at >= self.zones_every_steps:
            traj = np.asarray(self.trajectory, np.float64).reshape(-1, 2)
            hist = view.rssi_history
            n = min(len(traj), len(hist))
            scores = router_scores(
                view.grid, view.routers_xy, traj[len(traj) - n :], hist[len(hist) - n :]
            )
            self._zone = np.argmax(scores, axis=0)
            self._zones_at = self.steps
        return self._zone

    def expected_gain(self, view: RobotView, cells: np.ndarray) -> np.ndarray:
        """Unknown cells the mapper would update with the robot at each of ``cells`` (N, 2)."""
        grid = view.grid
        _, _, unknown = belief_classes(view.belief_u8)
        zone = self._strongest(view)
        routers = np.asarray(view.routers_xy, np.float64)
        ends = grid.cell_to_world(cells)
        starts = routers[zone[cells[:, 0], cells[:, 1]]]
        length = np.linalg.norm(ends - starts, axis=1)
        n = max(2, int(np.ceil(length.max() / (0.5 * grid.resolution_m))) + 1)
        t = np.linspace(0.0, 1.0, n)
        pts = starts[:, None, :] + (ends - starts)[:, None, :] * t[None, :, None]
        rc = grid.world_to_cell(pts)
        h, w = grid.shape
        r = np.clip(rc[..., 0], 0, h - 1)
        c = np.clip(rc[..., 1], 0, w - 1)
        flat = r * w + c
        # Count each cell once per ray: sort the flat indices per row, count the changes.
        flat.sort(axis=1)
        first = np.ones_like(flat, bool)
        first[:, 1:] = flat[:, 1:] != flat[:, :-1]
        gain = (unknown.ravel()[flat] & first).sum(axis=1).astype(np.float64)
        foot = np.asarray(self._reach_offsets)
        fr = cells[:, None, 0] + foot[None, :, 0]
        fc = cells[:, None, 1] + foot[None, :, 1]
        inside = (fr >= 0) & (fr < h) & (fc >= 0) & (fc < w)  # footprint cells off the grid
        return gain + (unknown[fr.clip(0, h - 1), fc.clip(0, w - 1)] & inside).sum(axis=1)

    def _choose_goal(self, view: RobotView, paths: CostField) -> Goal | None:
        self.candidates = []
        mask = frontier_mask(view.belief_u8)
        if not mask.any():
            self._stop("no_frontiers")
            return None
        mask &= ~self._frontier_exclusion(view)
        approach = self._approach(paths)
        walled_off = mask & ~np.isfinite(approach)
        self.unreachable_until[walled_off] = self.steps + self.unreachable_ttl_steps
        mask &= np.isfinite(approach)
        cells = np.argwhere(mask)
        if len(cells) == 0:
            self._stop("all_blacklisted")
            return None
        if len(cells) > self.max_candidates:
            cells = cells[np.linspace(0, len(cells) - 1, self.max_candidates).astype(int)]
        dist = approach[cells[:, 0], cells[:, 1]]
        score = self.expected_gain(view, cells) / (dist + self.distance_offset_m)
        self.candidates = [
            ((int(r), int(c)), s) for (r, c), s in zip(cells.tolist(), score.tolist(), strict=True)
        ]
        i = int(np.argmax(score))
        target = (int(cells[i, 0]), int(cells[i, 1]))
        self._resume()
        return Goal(self._approach_cell(paths, target), target, "frontier")
