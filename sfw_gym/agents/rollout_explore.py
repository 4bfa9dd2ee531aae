"""Candidates ranked by the bits their paths really buy.

:class:`RolloutExplorer` is :class:`~sfw_gym.agents.predict_explore.PredictiveExplorer` with one
change: of its menu (frontier cells and cells beyond the frontier that the predictor calls
free), the ``ranked_candidates`` best by expected bits per metre are re-ranked by the mapper's
own update run dry (:class:`~sfw_gym.mapping.dry_run.DryRun`) along the first
``horizon_steps`` readings of each one's planned path
(:func:`~sfw_gym.navigation.path_gain.readings_along`: turns charged in steps), each reading's
router the one predicted strongest there and its k the walls between them
(:func:`~sfw_gym.navigation.path_gain.walls_crossed`) on the map named by ``walls_from``; the
score is the best-prefix rate (:func:`~sfw_gym.navigation.path_gain.best_prefix_rate`) or the
readings' total (``rank_by``), and the expected bits per metre breaks ties. The learned agent
is ``rollout-explore`` (:class:`sfw_gym.rl.predict_explore.RolloutExploreAgent`).

:class:`RolloutOracle` (privileged; ``oracle-rollout`` with the learned predictor,
:class:`sfw_gym.rl.predict_explore.RolloutOracleAgent`) takes, of the same menu, the candidate
that truly gains most in ``horizon_steps``: a copy of the env's mapper updated along each
candidate's readings with the true radio's readings there (the radio's own noise, drawn from
the oracle's generator). It is the ceiling of any ranker on this menu: what a perfect gain
model would choose.
"""

from __future__ import annotations

import copy
import itertools
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import ndimage

from sfw_gym.agents.base import RobotView
from sfw_gym.agents.oracles import OracleAgent
from sfw_gym.agents.predict_explore import PredictExploreSettings, PredictiveExplorer
from sfw_gym.core.config import setting
from sfw_gym.core.constants import NOT_HEARD_DBM
from sfw_gym.mapping.dry_run import DryRun
from sfw_gym.mapping.grid import belief_classes
from sfw_gym.navigation.path_gain import (
    best_prefix_rate,
    path_totals,
    readings_along,
    walls_crossed,
)
from sfw_gym.navigation.planning import CostField, cells_to_world
from sfw_gym.navigation.prediction import VISITED_BIT

#: What gives a hypothetical reading its k: the predicted map's walls or the belief's only.
WALLS_FROM = ("predicted", "belief")
#: How a path's bits per reading become its score: the best-prefix rate, or their total.
RANK_BY = ("rate", "total")
#: The candidates beyond the frontier cells: predict-explore's lattice of unknown cells
#: predicted free, or every unvisited cell believed or predicted free (a lattice, denser beside
#: believed or predicted walls).
MENUS = ("predicted_unknown", "unvisited_free")


@dataclass(frozen=True)
class RolloutExploreSettings(PredictExploreSettings):
    """The parameters of :class:`RolloutExplorer`.

    Attributes:
        ranked_candidates: How many of the best candidates by expected bits per metre are
            re-ranked by their paths' dry runs.
        horizon_steps: Readings simulated along each candidate's path.
        min_prefix_steps: The best-prefix rate's shortest prefix (a shorter path is charged
            this many steps).
        walls_from: ``"predicted"`` (walls where the predictor says ``p_wall >= 0.5``) or
            ``"belief"`` (the believed walls only) give each reading's k.
        rank_by: ``"rate"`` (the best-prefix rate: bits per step) or ``"total"`` (the bits of
            all ``horizon_steps`` readings).
        menu: The candidates besides the frontier cells (:data:`MENUS`):
            ``"unvisited_free"`` adds every cell believed or predicted free that the robot has
            not passed within ``visited_margin_m``, every ``beyond_stride_cells`` cells, and every
            ``wall_stride_cells`` within ``wall_band_m`` of a believed or predicted wall.
        visited_margin_m: ``"unvisited_free"``: how near the trajectory a cell counts visited.
        wall_band_m: ``"unvisited_free"``: the band beside walls where candidates are denser.
        wall_stride_cells: ``"unvisited_free"``: the lattice in that band.
    """

    ranked_candidates: int = setting(16, integer=True, ge=1)
    horizon_steps: int = setting(20, integer=True, ge=1)
    min_prefix_steps: int = setting(5, integer=True, ge=1)
    walls_from: str = setting("predicted", choices=WALLS_FROM)
    rank_by: str = setting("rate", choices=RANK_BY)
    menu: str = setting("predicted_unknown", choices=MENUS)
    visited_margin_m: float = setting(0.3, ge=0.0)
    wall_band_m: float = setting(0.3, ge=0.0)
    wall_stride_cells: int = setting(3, integer=True, ge=1)


class RolloutExplorer(PredictiveExplorer):
    """Predict-explore's menu, re-ranked by the dry-run rate of each path (module doc).

    Parameters: :class:`RolloutExploreSettings` (keyword arguments, checked).

    Attributes:
        last_ranked: The latest re-ranking: candidate indices, best first by expected bits per
            metre, and the score of each (``rank_by``), for studies.
    """

    name = "rollout-explore-nearest"

    settings_class = RolloutExploreSettings
    settings: RolloutExploreSettings

    def _on_reset(self, view: RobotView) -> None:
        super()._on_reset(view)
        self.last_ranked: tuple[np.ndarray, np.ndarray] = (np.zeros(0, int), np.zeros(0))

    def _pick(
        self,
        view: RobotView,
        paths: CostField,
        targets: np.ndarray,
        goals: np.ndarray,
        score: np.ndarray,
    ) -> int:
        top = self.top_candidates(score)
        if len(top) < 2:
            return int(np.argmax(score))
        rate = self.path_rates(view, paths, goals[top])
        self.last_ranked = (top, rate)
        best = np.lexsort((-score[top], -rate))[0]  # the rate, then bits per metre
        return int(top[best])

    def _beyond_cells(self, view: RobotView, paths: CostField) -> np.ndarray:
        s = self.settings
        if s.menu == "predicted_unknown":
            return super()._beyond_cells(view, paths)
        pred = self.prediction(view)
        res = view.grid.resolution_m
        visited = (self._codes & VISITED_BIT) > 0
        near_path = ndimage.distance_transform_edt(~visited) * res <= s.visited_margin_m
        walls = pred.p_wall >= 0.5
        beside_wall = ndimage.distance_transform_edt(~walls) * res <= s.wall_band_m
        lattice = _lattice(view.grid.shape, s.beyond_stride_cells)
        lattice |= beside_wall & _lattice(view.grid.shape, s.wall_stride_cells)
        mask = lattice & (pred.p_free >= s.min_p_free) & ~near_path
        mask &= paths.reachable() & ~self.blacklisted & ~self.finder.frontier(view)
        return np.argwhere(mask)

    def top_candidates(self, score: np.ndarray) -> np.ndarray:
        """The ``ranked_candidates`` best candidates by ``score``, best first."""
        return np.argsort(-score, kind="stable")[: self.settings.ranked_candidates]

    def readings(
        self, view: RobotView, paths: CostField, goals: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """Where the robot would read along each goal's planned path (``horizon_steps`` at
        most), the paths one after another, and where each begins."""
        s = self.settings
        step_m = view.max_linear_speed_m_s * view.control_period_s
        turn = view.max_angular_speed_rad_s * view.control_period_s
        xy, starts = [], []
        n = 0
        for goal in goals.tolist():
            cells = paths.path((goal[0], goal[1]))[1:]
            along = readings_along(
                cells_to_world(view.grid, cells), view.odometry_pose, step_m, turn, s.horizon_steps
            )
            starts.append(n)
            xy.append(along)
            n += len(along)
        return np.concatenate(xy) if n else np.zeros((0, 2)), np.array(starts, np.int64)

    def reading_walls(self, view: RobotView) -> np.ndarray:
        """The walls that give a hypothetical reading its k (``walls_from``)."""
        if self.settings.walls_from == "belief":
            return belief_classes(view.belief_u8)[1]
        return self.prediction(view).p_wall >= 0.5

    def reading_routers(self, view: RobotView, xy: np.ndarray) -> np.ndarray:
        """The router predicted strongest at each reading (the one whose ray the mapper
        follows)."""
        grid = view.grid
        rc = grid.world_to_cell(xy) if len(xy) else np.zeros((0, 2), np.int64)
        rows = np.clip(rc[:, 0], 0, grid.n_rows - 1)
        cols = np.clip(rc[:, 1], 0, grid.n_cols - 1)
        return self.finder.strongest_router(view)[rows, cols]

    def path_bits(self, view: RobotView, xy: np.ndarray, starts: np.ndarray) -> np.ndarray:
        """Bits per reading along the paths: the mapper's update run dry."""
        router = self.reading_routers(view, xy)
        k = walls_crossed(view.grid, self.reading_walls(view), view.routers_xy, router, xy)
        return DryRun.of_view(view).path_gains(xy, router, k, starts)

    def path_rates(self, view: RobotView, paths: CostField, goals: np.ndarray) -> np.ndarray:
        """Each goal's path scored by ``rank_by`` from its readings' bits."""
        xy, starts = self.readings(view, paths, goals)
        gains = self.path_bits(view, xy, starts)
        if self.settings.rank_by == "total":
            return path_totals(gains, starts)
        return best_prefix_rate(gains, starts, self.settings.min_prefix_steps)


@dataclass(frozen=True)
class RolloutOracleSettings(RolloutExploreSettings):
    """:class:`RolloutExploreSettings`, ranking by the readings' total: the most bits in
    ``horizon_steps``."""

    rank_by: str = setting("total", choices=RANK_BY)


class RolloutOracle(OracleAgent, RolloutExplorer):
    """The candidate that truly gains most in ``horizon_steps`` (privileged; module doc)."""

    name = "oracle-rollout-nearest"

    settings_class = RolloutOracleSettings
    settings: RolloutOracleSettings

    def path_bits(self, view: RobotView, xy: np.ndarray, starts: np.ndarray) -> np.ndarray:
        """Bits per reading along the paths, from the env's own mapper fed the true radio."""
        return true_path_bits(self._env, xy, starts, self.rng)


def _lattice(shape: tuple[int, int], stride: int) -> np.ndarray:
    """Cells every ``stride`` rows and columns."""
    out = np.zeros(shape, bool)
    out[stride // 2 :: stride, stride // 2 :: stride] = True
    return out


def true_path_bits(
    env: Any, xy: np.ndarray, starts: np.ndarray, rng: np.random.Generator
) -> np.ndarray:
    """Bits per reading along each path (``xy`` one after another from ``starts``) that the env's
    mapper would gain from the true radio's readings there (privileged): a copy of the mapper
    per path, the radio's mean RSSI plus its noise from ``rng``; no physics, no bumps."""
    radio = env.ground_truth().radio
    cfg = radio.config
    mean = radio.mean_rssi(xy) if len(xy) else np.zeros((0, radio.n_routers))
    noise = rng.normal(0.0, cfg.noise_sigma_db, mean.shape) if cfg.noise_sigma_db > 0 else 0.0
    rssi = np.rint(mean + noise)
    rssi[rssi < cfg.sensitivity_dbm] = NOT_HEARD_DBM
    out = np.zeros(len(xy))
    for a, b in itertools.pairwise(np.append(starts, len(xy))):
        mapper = copy.deepcopy(env.mapper)
        for i in range(a, b):
            out[i] = mapper.update(xy[i], rssi[i])
    return out
