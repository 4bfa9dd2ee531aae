"""Frontier exploration plus the paper's cross-connecting passes between router dominance zones.

The sparse mapper updates only along the strongest router's ray (Kim et al., arXiv:2408.07757).
A cell owned by router A near the border of B's zone lies on A-rays only to points beyond it, in
B's zone, where the robot uses B's rays instead; so a band of unknown cells stays along the
borders between dominance zones. The paper's remedy is to cross those borders on purpose.

The robot estimates the zones itself: a multi-wall log-distance model of every router
(``rssi = c − 10 n log10 d − wall_loss · walls``, one tx power for all, walls counted on its own
belief map), corrected near its path by the residuals of its own RSSI history (inverse-distance
weighting). Cells within ``band_m`` of an estimated zone border form the bands. Then:

- the main route favours the bands: a frontier cluster's size counts its band cells
  ``1 + band_bonus`` times (in walled homes the borders mostly run along walls, and the unknown
  band cells are the wall-side cells that only the robot's footprint resolves);
- where a border crosses open space (no believed wall on the crossing) and an unknown band
  cluster lies within ``pass_trigger_m`` of the robot, it inserts a short cross-connecting pass:
  a closed loop of two legs along the border, one on each side ``pass_offset_m`` from it, joined
  by two crossings perpendicular to it. The far leg lays trajectory points beyond the band on the
  near router's rays; the near leg then updates the band between them, and the second crossing
  does the same for the other router's side. Passes keep ``pass_spacing_m`` apart.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit
from scipy import ndimage

from sfw_gym.agents.base import RobotView
from sfw_gym.agents.frontier import _UNCERTAIN, FrontierAgent, FrontierSettings, Goal
from sfw_gym.core.config import setting
from sfw_gym.mapping.grid import GridSpec
from sfw_gym.navigation.planning import CostField, belief_classes, mark_disk
from sfw_gym.navigation.radio_zones import dominance_bands, router_scores, wall_crossings


@dataclass(frozen=True)
class CrossPassSettings(FrontierSettings):
    """The parameters of :class:`CrossPassAgent`.

    Attributes:
        band_m: Half-width of the band along a zone border whose unknown cells a pass targets.
        min_band_area_m2: Unknown band clusters smaller than this get no pass.
        pass_trigger_m: A pass is inserted only for bands within this path distance.
        pass_length_m: Length of each leg along the border.
        pass_offset_m: Distance of each leg from the border.
        zones_every_steps: Re-estimate the zones this often.
        band_bonus: A frontier cluster's size counts its cells in an estimated border band
            ``1 + band_bonus`` times (the main route favours the bands).
        wall_loss_db: Loss per believed wall in the zone model (a prior).
        pass_spacing_m: No new pass within this distance of an earlier one.
        search_radius_m: The first path search's bound (see :class:`FrontierSettings`); a plan
            is kept on it only when no band cell lies within ``pass_trigger_m``, which it can
            tell only when it reaches that far (it does by default).
    """

    band_m: float = setting(0.8, ge=0.05)
    min_band_area_m2: float = setting(0.3, ge=0.0)
    pass_trigger_m: float = setting(5.0, ge=0.0)
    pass_length_m: float = setting(1.5, ge=0.1)
    pass_offset_m: float = setting(0.5, ge=0.05)
    zones_every_steps: int = setting(50, integer=True, ge=1)
    band_bonus: float = setting(2.0, ge=0.0)
    wall_loss_db: float = setting(10.0, ge=0.0)
    pass_spacing_m: float = setting(3.0, ge=0.0)
    search_radius_m: float = setting(5.0, gt=0.0)


class CrossPassAgent(FrontierAgent):
    """:class:`FrontierAgent` that favours router-zone border bands and crosses them in passes.

    Parameters: :class:`CrossPassSettings` (keyword arguments, checked).
    """

    name = "cross-pass"
    _committed_kinds = ("pass",)

    settings_class = CrossPassSettings
    settings: CrossPassSettings

    def _on_reset(self, view: RobotView) -> None:
        super()._on_reset(view)
        self.passed = np.zeros(view.grid.shape, bool)  # band cells a pass has targeted
        self.n_passes = 0
        self._zones_at = -(10**9)
        self.scores: np.ndarray | None = None
        self.zone: np.ndarray | None = None
        self.band: np.ndarray | None = None

    def _update_zones(self, view: RobotView) -> None:
        if (
            self.steps - self._zones_at < self.settings.zones_every_steps
            and self.scores is not None
        ):
            return
        self._zones_at = self.steps
        traj = np.asarray(self.trajectory, np.float64).reshape(-1, 2)
        hist = view.rssi_history
        n = min(len(traj), len(hist))
        _, walls, _ = belief_classes(view.belief_u8)
        self.scores = router_scores(
            view.grid,
            view.routers_xy,
            traj[len(traj) - n :],
            hist[len(hist) - n :],
            walls=walls | self.bumps,
            wall_loss_db=self.settings.wall_loss_db,
        )
        self.zone, self.band = dominance_bands(
            self.scores, self.settings.band_m / view.grid.resolution_m
        )

    def _choose_goal(self, view: RobotView, paths: CostField) -> Goal | None:
        if len(view.routers_xy) > 1:
            self._update_zones(view)
            if not paths.complete:
                if self._pass_may_be_due(view, paths):
                    return _UNCERTAIN  # passes are planned on the whole map's paths
            elif (goal := self._pass_goal(view, paths)) is not None:
                self.n_passes += 1
                return goal
        return super()._choose_goal(view, paths)

    def _pass_may_be_due(self, view: RobotView, paths: CostField) -> bool:
        """Whether a bounded search cannot rule out a pass: a band target within the trigger
        (or the search stopped short of the trigger)."""
        trigger = self.settings.pass_trigger_m
        if paths.max_cost_m < trigger:
            return True
        return bool(self.unknown_band(view, within=paths.cumulative <= trigger).any())

    def _utilities(
        self, view: RobotView, clusters: list[np.ndarray], path_m: np.ndarray
    ) -> np.ndarray:
        """Frontier's utility, each band cell of a cluster counting ``1 + band_bonus`` cells."""
        size = np.array([len(c) for c in clusters], np.int64)
        if self.band is not None and self.settings.band_bonus > 0 and len(clusters):
            cells = np.concatenate(clusters)
            in_band = np.concatenate(([0], np.cumsum(self.band[cells[:, 0], cells[:, 1]])))
            ends = np.cumsum(size)
            size = size + self.settings.band_bonus * (in_band[ends] - in_band[ends - size])
        res = view.grid.resolution_m
        return self.settings.gain_scale * size * res - self.settings.potential_scale * np.asarray(
            path_m, float
        )

    def unknown_band(self, view: RobotView, within: np.ndarray | None = None) -> np.ndarray:
        """Unknown cells in the estimated border bands not yet targeted by a pass, less those
        :meth:`GoalFinder.exclusion` keeps from frontier goals; only ``within`` a mask if given
        (the exclusion is evaluated at the remaining cells alone)."""
        if self.band is None:
            return np.zeros(view.grid.shape, bool)
        _, _, unknown = belief_classes(view.belief_u8)
        band = self.band & unknown & ~self.passed
        if within is not None:
            band &= within
        flat = np.flatnonzero(band)
        band.ravel()[flat[self.finder.excluded_at(view, flat)]] = False
        return band

    def _pass_goal(self, view: RobotView, paths: CostField) -> Goal | None:
        res = view.grid.resolution_m
        targets = self.unknown_band(view, within=paths.reachable())
        if not targets.any():
            return None
        min_cells = self.settings.min_band_area_m2 / res**2
        for rows, cols in self._clusters_within_trigger(targets, paths.cumulative):
            if len(rows) < min_cells:
                continue
            self.passed[rows, cols] = True
            waypoints = self._pass_waypoints(view, paths, rows, cols)
            if len(waypoints) >= 2:
                centre = (int(np.median(rows)), int(np.median(cols)))
                mark_disk(self.passed, centre, self.settings.pass_spacing_m / res)
                return Goal(waypoints[0], waypoints[0], "pass", waypoints=waypoints[1:])
        return None

    def _clusters_within_trigger(
        self, targets: np.ndarray, cost: np.ndarray
    ) -> list[tuple[np.ndarray, np.ndarray]]:
        """The 8-connected clusters of ``targets`` whose nearest cell costs at most
        ``pass_trigger_m``, nearest first: ``(rows, cols)`` each.

        Filled from the cells within the trigger only; where two clusters are equally near, their
        order is the one ``np.argsort`` gives over all clusters of the map (as labelled by
        ``ndimage.label``), so the choice never depends on how the clusters were found.
        """
        w = targets.shape[1]
        seeds = np.flatnonzero(targets & (cost <= self.settings.pass_trigger_m))
        if len(seeds) == 0:
            return []
        cells, starts = _fill_from_seeds(targets, seeds)
        best = np.minimum.reduceat(cost.ravel()[cells], starts[:-1])
        if len(np.unique(best)) == len(best):
            return [
                divmod(np.sort(cells[a:b]), w)
                for a, b in (starts[i : i + 2] for i in np.argsort(best))
            ]
        labels, n = ndimage.label(targets, structure=np.ones((3, 3), bool))
        best_all = ndimage.minimum(np.where(labels > 0, cost, np.inf), labels, np.arange(1, n + 1))
        nearest_first = []
        for i in np.argsort(best_all):
            if best_all[i] <= self.settings.pass_trigger_m:
                rows, cols = np.nonzero(labels == i + 1)
                nearest_first.append((rows, cols))
        return nearest_first

    def _pass_waypoints(
        self, view: RobotView, paths: CostField, rows: np.ndarray, cols: np.ndarray
    ) -> list[tuple[int, int]]:
        """A closed loop across the border at a band cluster: far leg, crossing, near leg, back."""
        assert self.scores is not None and self.zone is not None
        grid = view.grid
        c_rc = (int(np.median(rows)), int(np.median(cols)))
        a = int(self.zone[c_rc])
        others = [r for r in range(len(self.scores)) if r != a]
        scores = self.scores
        b = max(others, key=lambda r: scores[r][c_rc])
        diff = scores[a] - scores[b]
        gy, gx = np.gradient(diff)
        normal = np.array([gx[c_rc], gy[c_rc]])
        if not np.isfinite(normal).all() or np.linalg.norm(normal) < 1e-9:
            normal = view.routers_xy[a] - view.routers_xy[b]
        normal = normal / max(np.linalg.norm(normal), 1e-9)  # towards router a's side
        tangent = np.array([-normal[1], normal[0]])
        centre = grid.cell_to_world(np.array(c_rc))
        # Move the centre onto the border: along the normal by diff / |gradient| (dB / dB-per-m).
        slope = float(np.hypot(gx[c_rc], gy[c_rc])) / grid.resolution_m
        if np.isfinite(slope) and slope > 1e-6:
            centre = centre - normal * np.clip(
                diff[c_rc] / slope, -self.settings.band_m, self.settings.band_m
            )
        half, off = 0.5 * self.settings.pass_length_m, self.settings.pass_offset_m
        _, walls, _ = belief_classes(view.belief_u8)
        crossing = np.stack([centre - normal * off, centre + normal * off])
        if wall_crossings(grid, walls | self.bumps, crossing[:1], crossing[1:])[0, 0]:
            return []  # the border runs along a wall: the band bonus of the route covers it
        corners = [
            centre - normal * off - tangent * half,  # far side (router b's zone)
            centre - normal * off + tangent * half,
            centre + normal * off + tangent * half,  # near side (router a's zone)
            centre + normal * off - tangent * half,
        ]
        # Start at the corner nearest the robot, keep the loop's order, close it.
        start = int(np.argmin([np.linalg.norm(p - view.xy) for p in corners[:2]]))
        if start == 1:
            corners = [corners[1], corners[0], corners[3], corners[2]]
        corners.append(corners[0])
        out: list[tuple[int, int]] = []
        for p in corners:
            cell = self._snap(paths, grid, p, centre)
            if cell is not None and (not out or cell != out[-1]):
                out.append(cell)
        return out

    @staticmethod
    def _snap(
        paths: CostField, grid: GridSpec, p: np.ndarray, towards: np.ndarray
    ) -> tuple[int, int] | None:
        """The first reachable cell from ``p`` towards ``towards`` (None if none)."""
        h, w = grid.shape
        for t in np.linspace(0.0, 1.0, 8):
            q = p + (towards - p) * t
            r, c = (int(v) for v in grid.world_to_cell(q))
            if 0 <= r < h and 0 <= c < w and np.isfinite(paths.cumulative[r, c]):
                return r, c
        return None


@njit(cache=True)
def _fill_from_seeds(mask, seeds):  # pragma: no cover (compiled)
    """The 8-connected components of ``mask`` that hold a seed (flat indices): their cells (flat,
    grouped by component, in the order of the seeds first met) and each group's start (with the
    end appended)."""
    h, w = mask.shape
    flat = mask.ravel()
    seen = np.zeros(h * w, np.bool_)
    cells = np.empty(h * w, np.int64)
    starts = [0]
    n = 0
    for seed in seeds:
        if seen[seed]:
            continue
        seen[seed] = True
        cells[n] = seed
        head = n
        n += 1
        while head < n:
            i = cells[head]
            head += 1
            r0, c0 = i // w, i % w
            for r in range(max(r0 - 1, 0), min(r0 + 2, h)):
                for c in range(max(c0 - 1, 0), min(c0 + 2, w)):
                    j = r * w + c
                    if flat[j] and not seen[j]:
                        seen[j] = True
                        cells[n] = j
                        n += 1
        starts.append(n)
    return cells[:n].copy(), np.array(starts, np.int64)
