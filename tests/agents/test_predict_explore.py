"""The predictive explorer (issue 46): greedy bits per metre with the gain and the paths read off
a predicted map. Here with the predictors that learn nothing (no torch); the learned
``predict-explore`` runs through every registered agent's tests (its object graph holds no
ground truth, same seed same decisions)."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import sfw_gym  # noqa: F401 (registration)
from sfw_gym.agents.frontier import FrontierAgent, Goal
from sfw_gym.agents.predict_explore import PredictiveExplorer
from sfw_gym.core.errors import ConfigError
from sfw_gym.navigation.planning import cost_field
from sfw_gym.navigation.prediction import UNKNOWN, PredictedMap
from tests.agents.test_agents import FakeEnv

SMALL = "SfW-ExploreSmall-v0"


def run(agent, steps: int, seed: int = 2):
    env = gym.make(SMALL)
    obs, _ = env.reset(seed=seed)
    agent.reset(env, seed=seed)
    for _ in range(steps):
        obs, *_ = env.step(agent.act(obs))
    return env


def test_it_re_predicts_as_often_as_asked_and_keeps_the_belief_on_top():
    agent = PredictiveExplorer(predict_every_steps=25)
    env = run(agent, 100)
    assert 4 <= agent.n_predictions <= 6  # at replans, at most every 25 steps
    view = env.unwrapped.robot_view()
    predicted = agent.prediction(view)
    codes = agent._inputs.codes(view)
    free, wall = (codes & 3) == 0, (codes & 3) == 1
    assert np.all(predicted.p_free[free] == 1.0) and np.all(predicted.p_wall[wall] == 1.0)
    assert agent.decisions, "it chose goals"


def test_unknown_cells_cost_by_their_predicted_wall_probability():
    agent = PredictiveExplorer(predictor="prior", unknown_wall_cost=8.0, predicted_band_weight=0.0)
    env = run(agent, 30)
    view = env.unwrapped.robot_view()
    cost = agent._costs(view)
    base = FrontierAgent._costs(agent, view)
    unknown = ((agent._inputs.codes(view) & 3) == UNKNOWN) & np.isfinite(base)
    p_wall = agent.prediction(view).p_wall
    expected = base - agent.settings.unknown_cost + 1.0 + 8.0 * p_wall
    np.testing.assert_allclose(cost[unknown], expected[unknown])
    known = ~unknown & np.isfinite(base)
    np.testing.assert_array_equal(cost[known], base[known])


def test_a_goal_within_the_switch_margin_is_kept():
    agent = PredictiveExplorer(switch_margin=0.25)
    run(agent, 5)
    targets = np.array([[1, 1], [2, 2], [3, 3]])
    agent.goal = Goal((2, 2), (2, 2), "frontier")
    assert agent._keep_or_switch(targets, np.array([1.0, 1.1, 1.3])) == 1  # 1.1 · 1.25 ≥ 1.3
    assert agent._keep_or_switch(targets, np.array([1.0, 1.1, 1.5])) == 2
    agent.goal = None
    assert agent._keep_or_switch(targets, np.array([1.0, 1.1, 1.3])) == 2


def test_candidates_beyond_the_frontier_are_where_free_space_is_predicted():
    class AllFree:
        def predict_codes(self, codes, proximity):
            ones = np.ones(codes.shape, np.float32)
            return PredictedMap.with_belief(codes, ones, 0 * ones, 0 * ones)

    agent = PredictiveExplorer(beyond_stride_cells=3)
    agent.predictor = AllFree()
    env = run(agent, 20)
    view = env.unwrapped.robot_view()
    field = cost_field(agent._costs(view), view.cell, view.grid.resolution_m)
    beyond = agent._beyond_cells(view, field)
    assert len(beyond) > 0
    codes = agent._inputs.codes(view)
    assert np.all((codes[beyond[:, 0], beyond[:, 1]] & 3) == UNKNOWN)
    assert np.all(beyond % 3 == 1)  # the lattice
    assert not agent.finder.frontier(view)[beyond[:, 0], beyond[:, 1]].any()


def test_an_unknown_predictor_is_refused():
    with pytest.raises(ConfigError, match="predictor"):
        PredictiveExplorer(predictor="oracle")


def test_a_band_around_predicted_walls_raises_the_cost_beside_them():
    class WallAcross:
        """Free everywhere, but a wall predicted along row 20 (unknown cells only)."""

        def predict_codes(self, codes, proximity):
            p_wall = np.zeros(codes.shape, np.float32)
            p_wall[20] = 0.9
            return PredictedMap.with_belief(codes, 1 - p_wall, p_wall, 0 * p_wall)

    costs = {}
    for weight in (0.0, 1.0):
        agent = PredictiveExplorer(predicted_band_weight=weight, unknown_wall_cost=0.0)
        agent.predictor = WallAcross()
        env = run(agent, 10)
        view = env.unwrapped.robot_view()
        costs[weight] = agent._costs(view)
        unknown = agent._unknown(view)
    beside = unknown[21] & np.isfinite(costs[0.0][21])  # one cell off the predicted wall
    assert beside.any()
    assert np.all(costs[1.0][21][beside] > costs[0.0][21][beside])
    far = unknown[35] & np.isfinite(costs[0.0][35])  # beyond the band: unchanged
    np.testing.assert_array_equal(costs[1.0][35][far], costs[0.0][35][far])


def test_a_step_predicts_once_however_often_its_planning_asks():
    agent = PredictiveExplorer(predict_every_steps=1)
    env = run(agent, 3)
    view = env.unwrapped.robot_view()
    first = agent.prediction(view)
    n = agent.n_predictions
    assert agent.prediction(view) is first and agent.n_predictions == n
    assert agent.prediction(env.unwrapped.robot_view()) is not first  # a new view: anew


class GivenPrediction:
    """A predictor that returns fixed ``p_free`` and ``spread`` (``p_wall`` 0) on unknown cells."""

    def __init__(self, p_free: np.ndarray, spread: np.ndarray) -> None:
        self.p_free, self.spread = p_free, spread

    def predict_codes(self, codes, proximity):
        return PredictedMap.with_belief(codes, self.p_free, 0 * self.p_free, self.spread)


def reference_scores(unknown, p_free, spread, robot_col, router_col, frontier_cols):
    """The documented score on a one-row map with unit cell costs, walked cell by cell: expected
    bits ``p_free(c) · (1 − spread(c)) · (footprint + Σ_ray reach · bits)`` (1 bit an unknown
    cell; the footprint is c − 1 .. c + 1; the ray runs from beyond the robot's radius, 2 cells,
    to the router's cell, reach the running product of p_free, 1 on free cells) over metres of
    path (to the cell beside a frontier target, whose footprint covers it; to a beyond cell
    itself) + 0.3 m per radian of turn (0 ahead, π behind) + the 1 m offset."""
    n = len(unknown)
    p = np.where(unknown, p_free, 1.0)
    scores = {}
    for c in [*frontier_cols, *np.flatnonzero(unknown & (p_free >= 0.5))]:
        c = int(c)
        if c in scores:
            continue
        bits = sum(int(unknown[k]) for k in (c - 1, c, c + 1) if 0 <= k < n)
        step = 1 if router_col > c else -1
        reach = 1.0
        for k in range(c + 2 * step, router_col + step, step):
            reach *= p[k]
            if reach < 1e-3:
                break
            bits += reach * unknown[k]
        gain = p_free[c] * (1.0 - spread[c]) * bits
        towards_robot = 1 if robot_col > c else -1
        goal_col = c + towards_robot if c in frontier_cols else c  # a frontier: the cell beside
        metres = abs(goal_col - robot_col) * 0.1
        turn = 0.0 if c > robot_col else np.pi
        scores[(0, c)] = gain / (metres + 0.3 * turn + 1.0)
    return scores


def test_the_chosen_candidate_has_the_best_score_computed_by_hand():
    """One row of 30 cells, free over columns 8-19, the robot at column 14 facing +x, its router
    at column 13; a fixed random prediction on the unknown cells (one hopeless cell, p_free 0,
    that ends the rays through it; one below ``min_p_free``). Candidates: the two frontier cells
    and every unknown cell predicted free enough (stride 1). Each score and the choice are
    checked against :func:`reference_scores`, not the agent's own scoring."""
    rng = np.random.default_rng(7)
    unknown = np.ones(30, bool)
    unknown[8:20] = False
    p_free = rng.uniform(0.55, 0.95, 30)
    p_free[3], p_free[26] = 0.0, 0.4
    spread = rng.uniform(0.0, 0.3, 30)
    belief = np.where(unknown, 127, 255).astype(np.uint8)[None]
    env = FakeEnv(belief, pose=(1.45, 0.05, 0.0), routers=((1.35, 0.05),))
    agent = PredictiveExplorer(
        beyond_stride_cells=1,
        min_frontier_size_m=0.0,
        min_unknown_region_m2=0.0,
        turn_cost_m_per_rad=0.3,
        distance_offset_m=1.0,
        spread_penalty=1.0,
    )
    agent.reset(env, seed=0)
    agent.predictor = GivenPrediction(
        np.where(unknown, p_free, 0.0).astype(np.float32)[None],
        np.where(unknown, spread, 0.0).astype(np.float32)[None],
    )
    agent.act(None)
    expected = reference_scores(unknown, p_free, spread, 14, 13, (7, 20))
    assert sorted(dict(agent.candidates)) == sorted(expected)
    assert dict(agent.candidates) == pytest.approx(expected, rel=1e-6)  # float32 predictions
    best = max(expected, key=expected.get)
    assert agent.goal.target == best, (best, expected)
