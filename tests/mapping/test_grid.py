"""GridSpec geometry and the compiled ray traversal."""

from __future__ import annotations

import numpy as np
import pytest

from sfw_gym.core.errors import ConfigError
from sfw_gym.mapping import GridSpec, belief_classes, ray_cells

UNIT = GridSpec((0.0, 0.0), 1.0, (5, 5))


def cells(start, end, grid=UNIT):
    return [tuple(c) for c in ray_cells(grid, start, end).tolist()]


def test_covering_exact_and_with_margin():
    g = GridSpec.covering((0.0, 0.0, 15.0, 15.0), 0.05)
    assert g.shape == (300, 300)
    assert g.origin_xy == (0.0, 0.0)
    g = GridSpec.covering((0.0, 0.0, 15.0, 10.0), 0.05, margin_m=0.2)
    assert g.origin_xy == pytest.approx((-0.2, -0.2))
    assert g.shape == (208, 308)  # rows follow y, columns follow x
    assert g.bounds[2] >= 15.2 - 1e-9 and g.bounds[3] >= 10.2 - 1e-9


def test_rows_are_y_and_cols_are_x():
    g = GridSpec((1.0, 2.0), 0.1, (10, 20))
    assert g.world_to_cell((1.12, 2.31)).tolist() == [3, 1]
    assert g.cell_to_world((3, 1)).tolist() == pytest.approx([1.15, 2.35])
    assert g.n_rows == 10 and g.n_cols == 20


def test_a_point_s_clipped_cell_is_its_cell_inside_and_the_nearest_edge_cell_outside():
    g = GridSpec((-3.0, 4.5), 0.05, (40, 70))
    assert g.clipped_cell((-2.97, 4.58)) == (1, 0)
    assert g.clipped_cell((-2.97, 4.58, 1.0)) == (1, 0)  # a pose: its heading is ignored
    assert g.clipped_cell((-9.0, 0.0)) == (0, 0)
    assert g.clipped_cell((9.0, 99.0)) == (39, 69)
    assert all(type(v) is int for v in g.clipped_cell((0.0, 5.0)))


def test_round_trip_over_all_cells():
    g = GridSpec((-3.0, 4.5), 0.05, (40, 70))
    rr, cc = np.meshgrid(np.arange(40), np.arange(70), indexing="ij")
    rc = np.stack([rr, cc], axis=-1)
    centres = g.cell_to_world(rc)
    assert np.array_equal(g.world_to_cell(centres), rc)
    assert g.contains(centres).all()
    xs, ys = g.cell_centres()
    assert np.allclose(xs, centres[..., 0]) and np.allclose(ys, centres[..., 1])


def test_contains_edges():
    g = GridSpec((0.0, 0.0), 0.5, (2, 4))
    pts = np.array([[0.0, 0.0], [1.999, 0.999], [2.0, 0.5], [0.5, 1.0], [-1e-9, 0.5]])
    assert g.contains(pts).tolist() == [True, True, False, False, False]
    assert not g.contains(np.array([np.nan, 0.5]))


@pytest.mark.parametrize(
    "kwargs",
    [
        {"origin_xy": (0.0, 0.0), "resolution_m": 0.0, "shape": (2, 2)},
        {"origin_xy": (0.0, 0.0), "resolution_m": -1.0, "shape": (2, 2)},
        {"origin_xy": (np.nan, 0.0), "resolution_m": 0.1, "shape": (2, 2)},
        {"origin_xy": (0.0, 0.0), "resolution_m": 0.1, "shape": (0, 2)},
        {"origin_xy": (0.0, 0.0), "resolution_m": 0.1, "shape": (2.5, 2)},
        {"origin_xy": (0.0,), "resolution_m": 0.1, "shape": (2, 2)},
    ],
)
def test_bad_grid_raises(kwargs):
    with pytest.raises(ConfigError):
        GridSpec(**kwargs)


def test_bad_covering_raises():
    with pytest.raises(ConfigError, match="bounds"):
        GridSpec.covering((0.0, 0.0, -1.0, 1.0), 0.1)
    with pytest.raises(ConfigError, match="margin_m"):
        GridSpec.covering((0.0, 0.0, 1.0, 1.0), 0.1, margin_m=-0.1)


def test_belief_classes_thirds():
    free, wall, unknown = belief_classes(np.array([0, 84, 85, 127, 170, 171, 255], np.uint8))
    assert wall.tolist() == [True, True, False, False, False, False, False]
    assert free.tolist() == [False, False, False, False, False, True, True]
    assert unknown.tolist() == [False, False, True, True, True, False, False]


def test_ray_axis_aligned():
    assert cells((0.5, 0.5), (3.5, 0.5)) == [(0, 0), (0, 1), (0, 2), (0, 3)]
    assert cells((2.5, 4.5), (2.5, 1.5)) == [(4, 2), (3, 2), (2, 2), (1, 2)]
    assert cells((1.2, 1.2), (1.7, 1.9)) == [(1, 1)]  # inside one cell
    assert cells((1.5, 1.5), (1.5, 1.5)) == [(1, 1)]  # a point


def test_ray_diagonal_through_corners_steps_diagonally():
    assert cells((0.5, 0.5), (3.5, 3.5)) == [(0, 0), (1, 1), (2, 2), (3, 3)]
    assert cells((3.5, 0.5), (0.5, 3.5)) == [(0, 3), (1, 2), (2, 1), (3, 0)]


def test_ray_general_slope_and_reverse():
    fwd = cells((0.5, 0.5), (2.5, 1.5))
    assert fwd == [(0, 0), (0, 1), (1, 1), (1, 2)]
    assert cells((2.5, 1.5), (0.5, 0.5)) == fwd[::-1]


def test_ray_is_clipped_to_the_grid():
    assert cells((-2.0, 0.5), (1.5, 0.5)) == [(0, 0), (0, 1)]
    assert cells((4.5, 2.5), (9.0, 2.5)) == [(2, 4)]
    assert cells((-1.0, -1.0), (-3.0, 7.0)) == []


def test_ray_parameters_and_connectivity_random():
    rng = np.random.default_rng(0)
    g = GridSpec((-1.0, 2.0), 0.1, (37, 53))
    for _ in range(300):
        a = rng.uniform([-1.0, 2.0], [4.3, 5.7])
        b = rng.uniform([-1.0, 2.0], [4.3, 5.7])
        c, t = ray_cells(g, a, b, return_t=True)
        assert tuple(c[0]) == tuple(g.world_to_cell(a))
        assert tuple(c[-1]) == tuple(g.world_to_cell(b))
        steps = np.abs(np.diff(c, axis=0))
        assert (steps.max(axis=1) == 1).all()  # 4- or 8-neighbours, no gaps or repeats
        assert t[0, 0] == 0.0 and t[-1, 1] == pytest.approx(1.0)
        assert (np.diff(t, axis=1) >= 0).all() and np.allclose(t[1:, 0], t[:-1, 1])
        mid = a + (b - a) * t.mean(axis=1)[:, None]  # each cell holds its stretch's midpoint
        assert np.array_equal(g.world_to_cell(mid), c)


def test_ray_bad_input():
    with pytest.raises(ConfigError):
        ray_cells(UNIT, (np.nan, 0.0), (1.0, 1.0))
    with pytest.raises(ConfigError):
        ray_cells(UNIT, (0.0, 0.0, 0.0), (1.0, 1.0))


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"origin_xy": ("a", 0.0)}, r"origin_xy must be two numbers, got \('a', 0.0\)"),
        ({"origin_xy": (np.inf, 0.0)}, r"origin_xy must be finite, got \(inf, 0.0\)"),
        ({"resolution_m": "0.1"}, r"resolution_m must be a number, got '0.1'"),
        ({"resolution_m": True}, r"resolution_m must be a number, got True"),
        ({"resolution_m": np.nan}, r"resolution_m must be finite and > 0, got nan"),
        ({"shape": 4}, r"shape must be \(n_rows, n_cols\), got 4"),
        ({"shape": (0, 2)}, r"shape n_rows must be an int >= 1, got 0"),
        ({"shape": (2, -1)}, r"shape n_cols must be an int >= 1, got -1"),
    ],
)
def test_bad_grid_message_names_the_field_and_value(kwargs, message):
    """The error a user sees (the CLI prints it on one line) says which field is wrong."""
    args = {"origin_xy": (0.0, 0.0), "resolution_m": 0.1, "shape": (2, 2)} | kwargs
    with pytest.raises(ConfigError, match=message):
        GridSpec(**args)


def test_grid_fields_are_normalised_so_equal_grids_compare_and_hash_equal():
    g = GridSpec([1, 2], 1, [np.int64(3), 4])  # lists, ints, numpy ints
    assert g.origin_xy == (1.0, 2.0) and type(g.origin_xy[0]) is float
    assert g.resolution_m == 1.0 and type(g.resolution_m) is float
    assert g.shape == (3, 4) and type(g.shape) is tuple and type(g.shape[0]) is int
    assert g == GridSpec((1.0, 2.0), 1.0, (3, 4))
    assert hash(g) == hash(GridSpec((1.0, 2.0), 1.0, (3, 4)))
    assert GridSpec((0.0, 0.0), 0.1, (1, 1)).shape == (1, 1)  # a single cell is a grid


@pytest.mark.parametrize(
    ("bounds", "resolution", "message"),
    [
        ((0.0, 0.0, 1.0), 0.1, r"bounds must be \(xmin, ymin, xmax, ymax\)"),
        ((0.0, 0.0, np.inf, 1.0), 0.1, r"bounds must be finite"),
        ((0.0, 0.0, 0.0, 1.0), 0.1, r"bounds need xmax > xmin and ymax > ymin"),  # zero width
        ((0.0, 1.0, 1.0, 1.0), 0.1, r"bounds need xmax > xmin and ymax > ymin"),  # zero height
        ((0.0, 0.0, 1.0, 1.0), 0.0, r"resolution_m must be > 0, got 0.0"),
        ((0.0, 0.0, 1.0, 1.0), "0.1", r"resolution_m must be > 0, got '0.1'"),
    ],
)
def test_bad_covering_message(bounds, resolution, message):
    with pytest.raises(ConfigError, match=message):
        GridSpec.covering(bounds, resolution)


def test_covering_a_bound_smaller_than_a_cell_is_one_cell():
    g = GridSpec.covering((2.0, 3.0, 2.04, 3.01), 0.1)
    assert g.shape == (1, 1) and g.origin_xy == (2.0, 3.0)


def test_ray_bad_input_messages_and_point_shapes():
    with pytest.raises(ConfigError, match=r"start_xy and end_xy must be \(x, y\) pairs"):
        ray_cells(UNIT, (0.0, 0.0, 0.0), (1.0, 1.0))
    with pytest.raises(ConfigError, match="start_xy and end_xy must be finite"):
        ray_cells(UNIT, (0.5, 0.5), (np.inf, 1.0))
    # a point given as a (1, 2) row (e.g. one row of cell_to_world's output) is a point
    row = ray_cells(UNIT, np.array([[0.5, 0.5]]), np.array([[3.5, 0.5]]))
    assert row.tolist() == [[0, 0], [0, 1], [0, 2], [0, 3]]


def test_ray_buffer_holds_the_longest_traversal_of_a_tall_grid():
    from sfw_gym.mapping.raycast import ray_buffer_size

    tall = GridSpec((0.0, 0.0), 1.0, (50, 3))
    c = ray_cells(tall, (0.01, 0.01), (2.99, 49.99))  # corner to corner: rows + cols - 1 cells
    assert len(c) == 52 and len(c) <= ray_buffer_size(tall.shape)
    assert len(ray_cells(GridSpec((0.0, 0.0), 1.0, (3, 50)), (0.01, 0.01), (49.99, 2.99))) == 52
