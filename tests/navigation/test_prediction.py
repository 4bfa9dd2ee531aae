"""Map prediction's contract (issue 46): the inputs a predictor reads, the predicted map with the
belief folded in, the two predictors that learn nothing, and the expected gain on a predicted map
against a case computed by hand."""

from __future__ import annotations

import numpy as np
import pytest

from sfw_gym.agents.predict_explore import predicted_gain
from sfw_gym.core.constants import U8_FREE, U8_UNKNOWN, U8_WALL
from sfw_gym.mapping.grid import GridSpec
from sfw_gym.navigation.prediction import (
    FREE,
    INPUT_CHANNELS,
    OUTSIDE,
    UNKNOWN,
    VISITED_BIT,
    WALL,
    FreePriorPredictor,
    NearestKnownPredictor,
    PredictedMap,
    PredictorInputs,
    belief_class,
    input_channels,
    router_proximity,
    truth_class,
)
from sfw_gym.navigation.view import RobotView


def test_belief_and_truth_read_as_classes():
    belief = np.array([[U8_FREE, U8_WALL, U8_UNKNOWN, 200, 60, 150]], np.uint8)
    assert belief_class(belief).tolist() == [[FREE, WALL, UNKNOWN, FREE, WALL, UNKNOWN]]
    truth = np.array([[255, 0, 127]], np.uint8)
    assert truth_class(truth).tolist() == [[FREE, WALL, OUTSIDE]]


def test_inputs_mark_the_trajectory_and_the_routers():
    grid = GridSpec((0.0, 0.0), 0.5, (4, 6))
    belief = np.full((4, 6), U8_UNKNOWN, np.uint8)
    belief[1, :3] = U8_FREE
    traj = np.array([[0.25, 0.75], [0.75, 0.75], [1.25, 0.75]])
    view = RobotView.hand_made(
        belief,
        grid,
        (1.25, 0.75, 0.0),
        [[2.75, 1.75]],
        rssi_history=np.full((3, 1), -50),
        odometry_trajectory=traj,
    )
    inputs = PredictorInputs(view)
    codes = inputs.codes(view)
    assert ((codes & VISITED_BIT) > 0).tolist()[1] == [True, True, True, False, False, False]
    assert ((codes & VISITED_BIT) > 0).sum() == 3
    x = inputs.channels(view)
    assert x.shape == (len(INPUT_CHANNELS), 4, 6)
    assert x[INPUT_CHANNELS.index("unknown")].sum() == 21
    prox = x[INPUT_CHANNELS.index("router_proximity")]
    assert prox[3, 5] == pytest.approx(np.exp(0.0))  # the router's own cell
    assert prox[0, 0] == pytest.approx(np.exp(-np.hypot(2.5, 1.5) / 5.0), rel=1e-6)
    np.testing.assert_array_equal(router_proximity(grid, [[2.75, 1.75]]), prox)
    np.testing.assert_array_equal(input_channels(codes, prox), x)


def test_predicted_map_keeps_the_belief_where_it_knows():
    codes = np.array([[FREE, WALL, UNKNOWN | VISITED_BIT, UNKNOWN]], np.uint8)
    p = PredictedMap.with_belief(
        codes, np.full((1, 4), 0.3), np.full((1, 4), 0.6), np.full((1, 4), 0.2)
    )
    assert p.p_free[0].tolist() == pytest.approx([1.0, 0.0, 0.3, 0.3])
    assert p.p_wall[0].tolist() == pytest.approx([0.0, 1.0, 0.6, 0.6])
    assert p.spread[0].tolist() == pytest.approx([0.0, 0.0, 0.2, 0.2])


def test_the_predictors_that_learn_nothing():
    codes = np.array([[FREE, UNKNOWN, UNKNOWN, UNKNOWN, WALL]], np.uint8)
    prox = np.zeros((1, 5), np.float32)
    nearest = NearestKnownPredictor().predict_codes(codes, prox)
    assert nearest.p_free.tolist() == [[1.0, 1.0, 1.0, 0.0, 0.0]]  # a tie goes to the first
    assert nearest.p_wall.tolist() == [[0.0, 0.0, 0.0, 1.0, 1.0]]
    prior = FreePriorPredictor(0.7, 0.2).predict_codes(codes, prox)
    assert prior.p_free[0].tolist() == pytest.approx([1.0, 0.7, 0.7, 0.7, 0.0])
    assert prior.p_wall[0].tolist() == pytest.approx([0.0, 0.2, 0.2, 0.2, 1.0])
    blank = np.full((2, 2), UNKNOWN, np.uint8)  # nothing known: the prior
    assert NearestKnownPredictor().predict_codes(blank, prox[:, :2].repeat(2, 0)).p_free.shape == (
        2,
        2,
    )


def test_expected_gain_on_a_predicted_map_equals_the_hand_computed_case():
    """A 1 x 10 corridor of 1 m cells, all unknown (1 bit each) but cell 3 (believed free); the
    robot at cell 0, its router at cell 9. The footprint (cell 0 only) gives 1 bit; the ray
    gives each unknown cell's bit times the chance that the free stretch reaches it, the product
    of p_free from cell 1 on: 0.8, 0.4, (cell 3 known: 0), 0.2, 0.1, ... 0.00625; all times
    p_free(cell 0) = 0.9 and (1 - spread 0.1)."""
    grid = GridSpec((0.0, 0.0), 1.0, (1, 10))
    belief = np.full((1, 10), U8_UNKNOWN, np.uint8)
    belief[0, 3] = U8_FREE
    view = RobotView.hand_made(belief, grid, (0.5, 0.5, 0.0), [[9.5, 0.5]])
    p_free = np.array([[0.9, 0.8, 0.5, 1.0, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5]], np.float32)
    spread = np.zeros((1, 10), np.float32)
    spread[0, 0] = 0.1
    predicted = PredictedMap(p_free, 1.0 - p_free, spread)
    ray = 0.8 + 0.4 + 0.0 + 0.2 + 0.1 + 0.05 + 0.025 + 0.0125 + 0.00625
    expected = 0.9 * (1 - 0.1) * (1.0 + ray)
    gain = predicted_gain(
        view, predicted, np.array([[9.5, 0.5]]), np.array([[0, 0]]), np.zeros((1, 2))
    )
    assert gain[0] == pytest.approx(expected, rel=1e-5)
    # a predicted wall right beside the robot: the footprint's bit only
    p_free[0, 1] = 0.0
    predicted = PredictedMap(p_free, 1.0 - p_free, spread)
    gain = predicted_gain(
        view, predicted, np.array([[9.5, 0.5]]), np.array([[0, 0]]), np.zeros((1, 2))
    )
    assert gain[0] == pytest.approx(0.9 * 0.9 * 1.0, rel=1e-5)
    # no uncertainty penalty: the spread is ignored
    gain = predicted_gain(
        view, predicted, np.array([[9.5, 0.5]]), np.array([[0, 0]]), np.zeros((1, 2)), 0.0
    )
    assert gain[0] == pytest.approx(0.9, rel=1e-5)


def test_a_ray_stops_at_the_grid_s_edge_and_says_whether_it_reached_its_target():
    from sfw_gym.navigation.candidates import ray_buffer, ray_cells

    origin, buf = np.zeros(2), ray_buffer((1, 10))
    open_ = np.zeros((1, 10), bool)
    cells, reached = ray_cells(0, 0, np.array([4.5, 0.5]), 0.4, origin, 1.0, open_, buf)
    assert reached and cells[:, 1].tolist() == [1, 1, 2, 2, 3, 3, 4, 4]  # half-cell samples
    cells, reached = ray_cells(0, 0, np.array([14.5, 0.5]), 0.4, origin, 1.0, open_, buf[:2])
    assert len(cells) == 18  # a buffer too short: a fresh array
    assert not reached and cells[:, 1].max() == 9
    wall = open_.copy()
    wall[0, 3] = True
    cells, reached = ray_cells(0, 0, np.array([4.5, 0.5]), 0.4, origin, 1.0, wall, buf)
    assert not reached and cells[:, 1].tolist() == [1, 1, 2, 2]  # stops before the wall
    assert cells.shape == (4, 2)  # (row, col) pairs, from the buffer as from a fresh array
    # the buffer holds the longest ray of its grid: corner to corner, sampled every half cell
    shape = (7, 12)
    corner = np.array([shape[1] - 0.5, shape[0] - 0.5])
    longest, _ = ray_cells(
        0, 0, corner, 0.0, origin, 1.0, np.zeros(shape, bool), np.empty((0, 2), np.int64)
    )
    assert ray_buffer(shape).shape[1] == 2 and len(ray_buffer(shape)) >= len(longest)
