"""Dense inverse k-visibility: the oracle map from the true k of every cell (Alg. 1)."""

from __future__ import annotations

import numpy as np
import pytest

from sfw_gym.core.errors import ConfigError
from sfw_gym.mapping import GridSpec, dense_inverse_k_visibility

GRID = GridSpec((0.0, 0.0), 1.0, (8, 10))
ROUTER = (2.5, 4.5)


def test_wall_cells_without_k_are_marked_wall():
    k = np.zeros(GRID.shape, np.int64)
    k[:, 5] = -1  # the wall's own cells
    k[:, 6:] = 1
    out = dense_inverse_k_visibility(GRID, ROUTER, k)
    expected = np.full(GRID.shape, 255, np.uint8)
    expected[1:, 5] = 0
    # No ray towards the router (row 4) crosses the wall in row 0: the 45-degree ray from
    # (0, 6) passes the corner into (1, 5). That cell has no k, so it stays unknown.
    expected[0, 5] = 127
    assert np.array_equal(out, expected)


def test_transition_between_neighbours_marks_the_far_cell():
    k = np.zeros(GRID.shape, np.int64)
    k[:, 5:] = 1
    out = dense_inverse_k_visibility(GRID, ROUTER, k)
    wall = out == 0
    assert wall[:, 5].sum() >= 6 and wall[2:7, 5].all()  # crossings around the router's row
    assert not wall[:, :5].any() and not wall[:, 6:].any()
    assert (out[~wall] == 255).all()


def test_adjacent_steps_off_ignores_steps_without_wall_cells():
    k = np.zeros(GRID.shape, np.int64)
    k[:, 5:] = 1  # a step between neighbours: on a rasterised plan, a shadow-line artefact
    out = dense_inverse_k_visibility(GRID, ROUTER, k, adjacent_steps=False)
    assert (out == 255).all()
    k[:, 5] = -1  # the wall has cells of its own: still found
    out = dense_inverse_k_visibility(GRID, ROUTER, k, adjacent_steps=False)
    assert (out[1:, 5] == 0).all() and (out[:, 6:] == 255).all() and (out[:, :5] == 255).all()


def test_line_of_sight_everywhere_is_all_free_and_unknown_stays_unknown():
    k = np.zeros(GRID.shape, np.int64)
    k[0, :] = -1  # outside the plan, with nothing known beyond
    out = dense_inverse_k_visibility(GRID, ROUTER, k)
    assert (out[1:] == 255).all()
    assert (out[0] == 127).all()


def test_two_walls_and_two_routers():
    k = np.zeros((2, *GRID.shape), np.int64)
    k[0][:, 3:] = 1
    k[0][:, 7:] = 2  # router 0 on the left sees walls before columns 3 and 7
    k[1][:, :7] = 1  # router 1 on the right sees only the wall before column 7
    out = dense_inverse_k_visibility(GRID, [ROUTER, (8.5, 4.5)], k)
    wall = out == 0
    # the far side of each crossing, as seen from each router: columns 3 and 7 from router 0,
    # column 6 from router 1
    assert wall[2:7, 3].all() and wall[:, 7].all() and wall[1:7, 6].all()
    assert not wall[:, [0, 1, 2, 4, 5, 8, 9]].any()
    assert (out[~wall] == 255).all()


def test_bad_input():
    k = np.zeros(GRID.shape, np.int64)
    with pytest.raises(ConfigError, match=rf"k_grid must .* got \({k.shape[0]}, 5\) for 1 router"):
        dense_inverse_k_visibility(GRID, ROUTER, k[:, :5])
    with pytest.raises(ConfigError, match="integer"):
        dense_inverse_k_visibility(GRID, ROUTER, k.astype(float))
    with pytest.raises(ConfigError, match="router_xy"):
        dense_inverse_k_visibility(GRID, (np.nan, 1.0), k)
