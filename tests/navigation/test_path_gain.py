"""What a path buys (issue 51): readings along a path with turns charged, walls crossed, and the
best-prefix rate, each against values worked out by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sfw_gym.mapping import GridSpec
from sfw_gym.navigation.path_gain import (
    best_prefix_rate,
    path_totals,
    readings_along,
    walls_crossed,
)


def test_readings_along_a_straight_path_step_by_step():
    path = np.array([(0.0, 0.0), (1.0, 0.0)])
    xy = readings_along(path, (0.0, 0.0, 0.0), 0.1, 0.3, horizon=5)
    np.testing.assert_allclose(xy, [(0.1 * i, 0.0) for i in range(1, 6)], atol=1e-12)
    assert len(readings_along(path, (0.0, 0.0, 0.0), 0.1, 0.3, horizon=50)) == 10  # path ends


def test_turning_back_costs_readings_in_place():
    path = np.array([(0.0, 0.0), (-1.0, 0.0)])
    xy = readings_along(path, (0.0, 0.0, 0.0), 0.1, 0.3, horizon=20)
    n_turn = int(math.pi / 0.3)  # 10 steps of 0.3 rad before it faces -x
    np.testing.assert_allclose(xy[:n_turn], 0.0)
    np.testing.assert_allclose(xy[n_turn], (-0.1, 0.0), atol=1e-12)
    assert len(xy) == 20


def test_a_corner_costs_its_turn():
    path = np.array([(0.0, 0.0), (0.2, 0.0), (0.2, 0.2)])
    xy = readings_along(path, (0.0, 0.0, 0.0), 0.1, 0.5, horizon=10)
    # 2 steps along x, int((pi/2) / 0.5) = 3 readings at the corner, 2 steps along y
    expected = [(0.1, 0), (0.2, 0), (0.2, 0), (0.2, 0), (0.2, 0), (0.2, 0.1), (0.2, 0.2)]
    np.testing.assert_allclose(xy, expected, atol=1e-12)


def test_walls_crossed_counts_runs_of_wall_cells():
    grid = GridSpec((0.0, 0.0), 0.1, (10, 40))
    walls = np.zeros(grid.shape, bool)
    walls[:, 10:12] = True  # a thick wall: one run
    walls[:, 25] = True
    routers = np.array([(0.25, 0.55)])
    xy = np.array([(0.8, 0.55), (2.0, 0.55), (3.5, 0.55), (3.5, 0.55)])
    k = walls_crossed(grid, walls, routers, np.array([0, 0, 0, -1]), xy)
    assert k.tolist() == [0, 1, 2, 0]


def test_best_prefix_rate_by_hand():
    gains = np.array([0.0, 0.0, 6.0, 0.0, 0.0, 0.0, 1.0, 1.0])
    # path 0: prefixes of >= 1 step: 0, 0, 2, 1.5, 1.2, 1.0 -> 2; path 1: (1 + 1) / 3 steps charged
    rate = best_prefix_rate(gains, np.array([0, 6]), min_steps=1)
    assert rate[0] == pytest.approx(2.0)
    assert best_prefix_rate(gains, np.array([0, 6]), min_steps=3)[1] == pytest.approx(2 / 3)
    assert best_prefix_rate(gains, np.array([0, 6]), min_steps=4)[0] == pytest.approx(1.5)
    np.testing.assert_allclose(path_totals(gains, np.array([0, 6, 8])), [6.0, 2.0, 0.0])
    # an empty path between two others rates 0, and the paths after it are still rated
    rate = best_prefix_rate(gains, np.array([0, 6, 6]), min_steps=1)
    assert rate.tolist() == pytest.approx([2.0, 0.0, 1.0])


def test_best_prefix_rate_does_not_favour_long_paths():
    rng = np.random.default_rng(0)
    for _ in range(50):
        g = rng.exponential(1.0, rng.integers(5, 30))
        base = best_prefix_rate(g, np.array([0]), 3)[0]
        padded = best_prefix_rate(np.append(g, np.zeros(20)), np.array([0]), 3)[0]
        assert padded == pytest.approx(base)  # steps that gain nothing change nothing
        longer = best_prefix_rate(np.append(g, g), np.array([0]), 3)[0]
        assert longer >= base  # more prefixes to choose from: never lower
        n = len(g)
        slower = best_prefix_rate(np.repeat(g / 2, 2), np.array([0]), 3)[0]
        assert slower <= base + 1e-12  # the same bits over twice the steps: no better
        assert best_prefix_rate(g[: n // 2 + 3], np.array([0]), 3)[0] <= base + 1e-12
