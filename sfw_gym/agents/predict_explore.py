"""Exploration on a predicted map: information gain where the map predictor expects it, per metre
of path planned through what it expects (MapEx's recipe for a WiFi mapper).

:class:`PredictiveExplorer` is :class:`~sfw_gym.agents.greedy.GreedyInfoGainAgent` with its two
guesses about the unseen made by a map predictor
(:class:`~sfw_gym.navigation.prediction.MapPredictor`) instead of assumed:

- **Candidates**: the greedy menu's frontier cells, and cells beyond the frontier (a lattice of
  unknown cells the predictor calls free), so that a robot may head for a room it has not seen.
- **Expected gain** at a candidate (:func:`predicted_gain`): the entropy of the unknown cells in
  the footprint, plus that of the unknown cells on the ray towards the router predicted strongest
  there, each weighted by the probability that the free stretch reaches it (the product of
  ``p_free`` along the ray from the candidate; the mapper marks free the stretch up to the first
  wall), all times the probability that the candidate itself is free and discounted by the
  predictor's ``spread`` there.
- **Cost**: the path's metres, plus ``turn_cost_m_per_rad`` per radian of turning towards the
  candidate (as frontier charges) and ``distance_offset_m``.
- **Paths**: an unknown cell costs ``1 + unknown_wall_cost · p_wall`` instead of a flat
  ``unknown_cost``: the planner goes through doorways it expects and around walls it expects.

The predictor is re-run every ``predict_every_steps`` (at a replan); in between, the newest
belief overrides the last prediction on the cells it knows. The learned agent is
``predict-explore`` (:class:`sfw_gym.rl.predict_explore.PredictExploreAgent`); this class alone
runs with a predictor that learns nothing (``predictor="nearest"``: the nearest known cell's
class), the ablation that says what the learning is worth.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numba import njit

from sfw_gym.agents.base import Decision, RobotView
from sfw_gym.agents.frontier import Goal
from sfw_gym.agents.greedy import GreedyInfoGainAgent, GreedySettings
from sfw_gym.core.config import setting
from sfw_gym.navigation.candidates import (
    footprint_bits,
    ray_buffer,
    ray_cells,
    unknown_bits_at,
)
from sfw_gym.navigation.menu import FEATURES
from sfw_gym.navigation.planning import CostField, WallBand, wall_cost_term, wall_distance_m
from sfw_gym.navigation.prediction import (
    UNKNOWN,
    FreePriorPredictor,
    MapPredictor,
    NearestKnownPredictor,
    PredictedMap,
    PredictorInputs,
)

#: The predictors that learn nothing, by name (the learned one is the ``rl`` extra's).
BASELINE_PREDICTORS = {"nearest": NearestKnownPredictor, "prior": FreePriorPredictor}
_NO_FEATURES = np.full(len(FEATURES), np.nan)


@dataclass(frozen=True)
class PredictExploreSettings(GreedySettings):
    """The parameters of :class:`PredictiveExplorer`.

    Attributes:
        predictor: ``"nearest"`` or ``"prior"`` (learn nothing); the learned agent's own.
        predict_every_steps: Re-predict at a replan at most this often.
        beyond_stride_cells: Candidates beyond the frontier lie on a lattice this many cells
            apart.
        min_p_free: A cell beyond the frontier is a candidate when predicted free with at
            least this probability.
        spread_penalty: A candidate's gain is multiplied by ``1 − spread_penalty · spread``.
        unknown_wall_cost: Planner cost of an unknown cell is ``1 + this · p_wall``.
        predicted_band_weight: The wall band around predicted walls costs this fraction of
            the band around believed walls (0: none).
        switch_margin: Keep the current goal while its score is within this fraction of the
            best candidate's (0: always the best).

    Greedy's ``zones_every_steps`` (100 here, greedy's 25) and ``replan_every_steps`` (10,
    frontier's 5) are set for the cost per step; the validation sweeps
    (docs/results/prediction.md) found no loss in either.
    """

    predictor: str = setting("nearest", choices=tuple(BASELINE_PREDICTORS))
    predict_every_steps: int = setting(40, integer=True, ge=1)
    beyond_stride_cells: int = setting(6, integer=True, ge=1)
    min_p_free: float = setting(0.5, ge=0.0, le=1.0)
    spread_penalty: float = setting(1.0, ge=0.0)
    unknown_wall_cost: float = setting(8.0, ge=0.0)
    predicted_band_weight: float = setting(1.0, ge=0.0)
    switch_margin: float = setting(0.0, ge=0.0)
    zones_every_steps: int = setting(100, integer=True, ge=1)
    replan_every_steps: int = setting(10, integer=True, ge=1)


class PredictiveExplorer(GreedyInfoGainAgent):
    """Greedy bits per metre, with the gain and the paths read off a predicted map.

    Parameters: :class:`PredictExploreSettings` (keyword arguments, checked).

    Attributes:
        predicted: The latest predicted map (with the newest belief folded in).
    """

    name = "predict-explore-nearest"

    settings_class = PredictExploreSettings
    settings: PredictExploreSettings

    def make_predictor(self) -> MapPredictor:
        """The map predictor this agent reads (built once, on first use: :attr:`predictor`)."""
        return BASELINE_PREDICTORS[self.settings.predictor]()

    @cached_property
    def predictor(self) -> MapPredictor:
        """The agent's map predictor (:meth:`make_predictor`, kept across episodes)."""
        return self.make_predictor()

    def _on_reset(self, view: RobotView) -> None:
        super()._on_reset(view)
        self._inputs = PredictorInputs(view)
        self._raw: PredictedMap | None = None
        self._predicted_at = -(10**9)
        self.predicted: PredictedMap | None = None
        self._predicted_view: RobotView | None = None
        self._codes = np.zeros(view.grid.shape, np.uint8)
        self._band = np.zeros(view.grid.shape)  # the planner's cost around predicted walls
        self.n_predictions = 0

    def prediction(self, view: RobotView) -> PredictedMap:
        """The predicted map now (re-predicted when ``predict_every_steps`` have passed; once
        per view: a step's planning asks several times)."""
        if view is self._predicted_view and self.predicted is not None:
            return self.predicted
        codes = self._inputs.codes(view)
        if (
            self._raw is None
            or self.steps - self._predicted_at >= self.settings.predict_every_steps
        ):
            self._raw = self.predictor.predict_codes(codes, self._inputs.proximity)
            self._predicted_at = self.steps
            self.n_predictions += 1
            self._band = self._predicted_wall_band(view, codes, self._raw.p_wall)
        raw = self._raw
        self.predicted = PredictedMap.with_belief(codes, raw.p_free, raw.p_wall, raw.spread)
        self._predicted_view, self._codes = view, codes
        return self.predicted

    def _unknown(self, view: RobotView) -> np.ndarray:
        """The cells the belief does not know (as the prediction of ``view`` read them)."""
        self.prediction(view)
        return (self._codes & 3) == UNKNOWN

    def _predicted_wall_band(
        self, view: RobotView, codes: np.ndarray, p_wall: np.ndarray
    ) -> np.ndarray:
        """The planner's wall band (:func:`~sfw_gym.navigation.planning.wall_cost_term`) around
        the unknown cells predicted to be walls, times ``predicted_band_weight`` (finite: a
        prediction may be wrong; the predicted wall itself costs ``unknown_wall_cost · p_wall``)."""
        walls = ((codes & 3) == UNKNOWN) & (p_wall >= 0.5)
        if not walls.any() or self.settings.predicted_band_weight == 0:
            return np.zeros(codes.shape)
        res = view.grid.resolution_m
        term = wall_cost_term(wall_distance_m(walls, res), res, WallBand(view.radius_m))
        term[~np.isfinite(term)] = 0.0
        return self.settings.predicted_band_weight * term

    def _costs(self, view: RobotView, relaxed: bool = False) -> np.ndarray:
        cost = super()._costs(view, relaxed)
        if relaxed:
            return cost
        p_wall = self.prediction(view).p_wall
        finite = np.isfinite(cost)
        unknown = self._unknown(view) & finite
        extra = 1.0 - self.settings.unknown_cost + self.settings.unknown_wall_cost * p_wall
        cost[unknown] += extra[unknown]
        cost[finite] += self._band[finite]
        return cost

    def expected_gain(self, view: RobotView, cells: np.ndarray) -> np.ndarray:
        """Bits the mapper is expected to gain with the robot at each of ``cells`` ``(N, 2)``,
        on the predicted map (:func:`predicted_gain`)."""
        cells = np.asarray(cells, np.int64).reshape(-1, 2)
        routers = np.asarray(view.routers_xy, np.float64)
        zone = self.finder.strongest_router(view)
        return predicted_gain(
            view,
            self.prediction(view),
            routers[zone[cells[:, 0], cells[:, 1]]],
            cells,
            self.finder.reach_offsets,
            self.settings.spread_penalty,
        )

    def _beyond_cells(self, view: RobotView, paths: CostField) -> np.ndarray:
        """Lattice cells beyond the frontier that the predictor calls free, reachable and not
        blacklisted ``(M, 2)``."""
        s = self.settings.beyond_stride_cells
        pred = self.prediction(view)
        mask = np.zeros(view.grid.shape, bool)
        mask[s // 2 :: s, s // 2 :: s] = True
        mask &= self._unknown(view)
        mask &= pred.p_free >= self.settings.min_p_free
        mask &= paths.reachable() & ~self.blacklisted & ~self.finder.frontier(view)
        return np.argwhere(mask)

    def _choose_goal(self, view: RobotView, paths: CostField) -> Goal | None:
        menu = self._info_gain_menu(view, paths, ("path_cost_m", "heading_change_rad"))
        if menu is None:
            return None
        beyond = self._beyond_cells(view, paths)
        targets = np.concatenate([menu.target_rc.reshape(-1, 2), beyond]).astype(np.int64)
        if not len(targets):
            self._stop("all_blacklisted")
            return None
        goals = np.concatenate([menu.goal_rc.reshape(-1, 2), beyond]).astype(np.int64)
        metres = np.concatenate(
            [menu.feature("path_cost_m"), paths.cumulative[beyond[:, 0], beyond[:, 1]]]
        )
        turn = np.concatenate(
            [menu.feature("heading_change_rad"), self.finder.heading_change(view, beyond)]
        )
        cost = metres + self.settings.turn_cost_m_per_rad * turn + self.settings.distance_offset_m
        score = self.expected_gain(view, targets) / cost
        self.candidates = list(zip(map(tuple, targets.tolist()), score.tolist(), strict=True))
        i = self._pick(view, paths, targets, goals, score)
        if i < len(menu):
            self._log_decision(menu, i)
        else:
            target = (int(targets[i, 0]), int(targets[i, 1]))
            self.decisions.append(Decision(self.steps, target, len(targets), _NO_FEATURES))
        self._resume()
        target = (int(targets[i, 0]), int(targets[i, 1]))
        return Goal((int(goals[i, 0]), int(goals[i, 1])), target, "frontier")

    def _pick(
        self,
        view: RobotView,
        paths: CostField,
        targets: np.ndarray,
        goals: np.ndarray,
        score: np.ndarray,
    ) -> int:
        """The candidate to drive to, given each one's ``score`` (expected bits per metre):
        :meth:`_keep_or_switch` here; a subclass may rank them otherwise."""
        return self._keep_or_switch(targets, score)

    def _keep_or_switch(self, targets: np.ndarray, score: np.ndarray) -> int:
        """The best candidate, unless the current goal's target is still one whose score is
        within ``switch_margin`` of the best (then that one: no dithering between goals)."""
        best = int(np.argmax(score))
        goal = self.goal
        if goal is None or self.settings.switch_margin <= 0:
            return best
        same = np.flatnonzero((targets[:, 0] == goal.target[0]) & (targets[:, 1] == goal.target[1]))
        if len(same) and score[same[0]] * (1 + self.settings.switch_margin) >= score[best]:
            return int(same[0])
        return best


def predicted_gain(
    view: RobotView,
    predicted: PredictedMap,
    routers_at: np.ndarray,
    cells: np.ndarray,
    footprint: np.ndarray,
    spread_penalty: float = 1.0,
) -> np.ndarray:
    """Expected bits at each of ``cells`` ``(N, 2)`` with the ray towards ``routers_at``
    ``(N, 2)`` (see the module doc): ``p_free(cell) · (1 − spread_penalty · spread(cell)) ·
    (footprint bits + Σ_ray P(stretch reaches) · bits)``."""
    grid = view.grid
    return _predicted_gains(
        view.log_odds,
        view.belief_u8,
        predicted.p_free.astype(np.float64),
        predicted.spread.astype(np.float64),
        np.asarray(routers_at, np.float64).reshape(-1, 2),
        np.asarray(cells, np.int64).reshape(-1, 2),
        np.asarray(footprint, np.int64).reshape(-1, 2),
        float(view.radius_m),
        np.asarray(grid.origin_xy, np.float64),
        float(grid.resolution_m),
        float(spread_penalty),
    )


@njit(cache=True)
def _predicted_gains(
    log_odds, belief, p_free, spread, routers, cells, footprint, radius, origin, res, penalty
):  # pragma: no cover (compiled)
    seen = np.zeros(belief.shape, np.int64)
    buf = ray_buffer(belief.shape)
    hopeless = p_free < 1e-3  # the stretch ends there (its reach would fall below 1e-3)
    out = np.zeros(len(cells))
    for i in range(len(cells)):
        mark = i + 1
        r0, c0 = cells[i, 0], cells[i, 1]
        total = footprint_bits(log_odds, belief, r0, c0, footprint, seen, mark)
        ray, _ = ray_cells(r0, c0, routers[i], radius, origin, res, hopeless, buf)
        reach = 1.0
        for k in range(len(ray)):
            r, c = ray[k, 0], ray[k, 1]
            if seen[r, c] == mark:
                continue
            seen[r, c] = mark
            reach *= p_free[r, c]
            if reach < 1e-3:
                break
            total += reach * unknown_bits_at(log_odds, belief, r, c)
        weight = p_free[r0, c0] * max(0.0, 1.0 - penalty * spread[r0, c0])
        out[i] = weight * total
    return out
