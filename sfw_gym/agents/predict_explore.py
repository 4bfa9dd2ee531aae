"""Exploration on a predicted map: information gain where the map predictor expects it, per metre
of path planned through what it expects (issue 46; MapEx's recipe for a WiFi mapper).

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
- **Paths**: an unknown cell costs ``1 + unknown_wall_cost · p_wall`` instead of a flat
  ``unknown_cost``: the planner goes through doorways it expects and around walls it expects.

The predictor is re-run every ``predict_every_steps`` (at a replan); in between, the newest
belief overrides the last prediction on the cells it knows. The learned agent is
``predict-explore`` (:class:`sfw_gym.rl.map_predictor.PredictExploreAgent`); this class alone
runs with a predictor that learns nothing (``predictor="nearest"``: the nearest known cell's
class), the ablation that says what the learning is worth.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from sfw_gym.agents.base import Decision, RobotView
from sfw_gym.agents.frontier import Goal
from sfw_gym.agents.greedy import GreedyInfoGainAgent, GreedySettings
from sfw_gym.core.config import setting
from sfw_gym.navigation.candidates import unknown_bits_at
from sfw_gym.navigation.menu import FEATURES
from sfw_gym.navigation.planning import CostField
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
    """

    predictor: str = setting("nearest", choices=tuple(BASELINE_PREDICTORS))
    predict_every_steps: int = setting(20, integer=True, ge=1)
    beyond_stride_cells: int = setting(4, integer=True, ge=1)
    min_p_free: float = setting(0.5, ge=0.0, le=1.0)
    spread_penalty: float = setting(1.0, ge=0.0)
    unknown_wall_cost: float = setting(8.0, ge=0.0)
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
        """The map predictor this agent reads."""
        return BASELINE_PREDICTORS[self.settings.predictor]()

    def _on_reset(self, view: RobotView) -> None:
        super()._on_reset(view)
        if not hasattr(self, "_predictor"):
            self._predictor = self.make_predictor()
        self._inputs = PredictorInputs(view)
        self._raw: PredictedMap | None = None
        self._predicted_at = -(10**9)
        self.predicted: PredictedMap | None = None
        self.n_predictions = 0

    def prediction(self, view: RobotView) -> PredictedMap:
        """The predicted map now (re-predicted when ``predict_every_steps`` have passed)."""
        codes = self._inputs.codes(view)
        if (
            self._raw is None
            or self.steps - self._predicted_at >= self.settings.predict_every_steps
        ):
            self._raw = self._predictor.predict_codes(codes, self._inputs.proximity)
            self._predicted_at = self.steps
            self.n_predictions += 1
        raw = self._raw
        self.predicted = PredictedMap.with_belief(codes, raw.p_free, raw.p_wall, raw.spread)
        return self.predicted

    def _costs(self, view: RobotView, relaxed: bool = False) -> np.ndarray:
        cost = super()._costs(view, relaxed)
        if relaxed:
            return cost
        p_wall = self.prediction(view).p_wall
        unknown = ((self._inputs.codes(view) & 3) == UNKNOWN) & np.isfinite(cost)
        extra = 1.0 - self.settings.unknown_cost + self.settings.unknown_wall_cost * p_wall
        cost[unknown] += extra[unknown]
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
        mask &= (self._inputs.codes(view) & 3) == UNKNOWN
        mask &= pred.p_free >= self.settings.min_p_free
        mask &= paths.reachable() & ~self.blacklisted & ~self.finder.frontier(view)
        return np.argwhere(mask)

    def _choose_goal(self, view: RobotView, paths: CostField) -> Goal | None:
        self.candidates = []
        if not self.finder.frontier(view).any():
            self._stop("no_frontiers")
            return None
        menu = self.finder.find(view, paths, sources=("info_gain",), features=("path_cost_m",))
        self.finder.mark_unreachable(
            menu.walled_off_rc, self.steps + self.settings.unreachable_ttl_steps
        )
        beyond = self._beyond_cells(view, paths)
        targets = np.concatenate([menu.target_rc.reshape(-1, 2), beyond]).astype(np.int64)
        if not len(targets):
            self._stop("all_blacklisted")
            return None
        goals = np.concatenate([menu.goal_rc.reshape(-1, 2), beyond]).astype(np.int64)
        metres = np.concatenate(
            [menu.feature("path_cost_m"), paths.cumulative[beyond[:, 0], beyond[:, 1]]]
        )
        score = self.expected_gain(view, targets) / (metres + self.settings.distance_offset_m)
        self.candidates = list(zip(map(tuple, targets.tolist()), score.tolist(), strict=True))
        i = int(np.argmax(score))
        if i < len(menu):
            self._log_decision(menu, i)
        else:
            target = (int(targets[i, 0]), int(targets[i, 1]))
            self.decisions.append(Decision(self.steps, target, len(targets), _NO_FEATURES))
        self._resume()
        target = (int(targets[i, 0]), int(targets[i, 1]))
        return Goal((int(goals[i, 0]), int(goals[i, 1])), target, "frontier")


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
    h, w = belief.shape
    seen = np.zeros(belief.shape, np.int64)
    out = np.zeros(len(cells))
    for i in range(len(cells)):
        mark = i + 1
        r0, c0 = cells[i, 0], cells[i, 1]
        total = 0.0
        for k in range(len(footprint)):
            r, c = r0 + footprint[k, 0], c0 + footprint[k, 1]
            if 0 <= r < h and 0 <= c < w and seen[r, c] != mark:
                seen[r, c] = mark
                total += unknown_bits_at(log_odds, belief, r, c)
        x0 = origin[0] + (c0 + 0.5) * res
        y0 = origin[1] + (r0 + 0.5) * res
        dx, dy = routers[i, 0] - x0, routers[i, 1] - y0
        length = np.hypot(dx, dy)
        n = int(np.ceil(length / (0.5 * res)))
        reach = 1.0
        for j in range(1, n + 1):
            t = j / n
            if t * length <= radius:
                continue  # the footprint, counted above
            r = int(np.floor((y0 + dy * t - origin[1]) / res))
            c = int(np.floor((x0 + dx * t - origin[0]) / res))
            if not (0 <= r < h and 0 <= c < w):
                break
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
