"""Navigation on the belief map: costs, Dijkstra paths, path resampling and pure pursuit.

Every expected value is worked out by hand in the test (geometry of a straight corridor, a cell
row next to a wall, an 8-connected grid of unit cost).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from sfw_gym.core.angles import wrap_angle
from sfw_gym.mapping.grid import GridSpec
from sfw_gym.navigation.planning import (
    PurePursuit,
    belief_classes,
    cells_to_world,
    cost_field,
    densify_path,
    disk_cells,
    disk_offsets,
    free_start,
    mark_contact,
    mark_disk,
    simplify_path,
    to_discrete,
    traversal_costs,
)

# ---------------------------------------------------------------- belief classes and costs


def test_belief_classes_split_at_the_thirds():
    b = np.array([0, 84, 85, 127, 170, 171, 255], np.uint8)
    free, wall, unknown = belief_classes(b)
    assert free.tolist() == [False, False, False, False, False, True, True]
    assert wall.tolist() == [True, True, False, False, False, False, False]
    assert unknown.tolist() == [False, False, True, True, True, False, False]


def test_costs_without_walls_are_one_for_free_and_unknown_cost_for_unknown():
    b = np.array([[255, 127, 200, 100]], np.uint8)
    cost = traversal_costs(b, 0.1, 0.2, unknown_cost=2.5)
    assert cost.tolist() == [[1.0, 2.5, 1.0, 2.5]]
    assert cost.dtype == np.float64


def test_cost_falls_linearly_from_the_robot_radius_to_radius_plus_clearance():
    # A row of 0.1 m cells with a wall in column 0: cell j lies j·0.1 m from the wall.
    # radius 0.25 + clearance 0.2 → band up to 0.45 m; extra = 8·clip((0.45 − d)/0.2, 0, 1):
    # d = 0.1, 0.2 → 8 (within the radius); d = 0.3 → 6; d = 0.4 → 2; d ≥ 0.5 → 0.
    b = np.full((1, 8), 255, np.uint8)
    b[0, 0] = 0
    cost = traversal_costs(b, 0.1, 0.25, inflation_cost=8.0, clearance_m=0.2)
    assert cost[0, 0] == np.inf  # the wall itself (lethal radius: half a cell)
    np.testing.assert_allclose(cost[0, 1:], [9.0, 9.0, 7.0, 3.0, 1.0, 1.0, 1.0])


def test_inflation_adds_to_the_unknown_cost_and_lethal_radius_widens_the_obstacle():
    b = np.full((1, 6), 127, np.uint8)
    b[0, 0] = 0
    cost = traversal_costs(b, 0.1, 0.25, unknown_cost=1.5, lethal_radius_m=0.2)
    # cells 1 and 2 lie within 0.2 m of the wall: obstacles; cell 3 (0.3 m): 1.5 + 6
    assert np.isinf(cost[0, :3]).all()
    np.testing.assert_allclose(cost[0, 3:], [7.5, 3.5, 1.5])


def test_blocked_cells_are_obstacles_like_walls():
    b = np.full((1, 6), 255, np.uint8)
    blocked = np.zeros((1, 6), bool)
    blocked[0, 5] = True
    cost = traversal_costs(b, 0.1, 0.25, blocked=blocked)
    np.testing.assert_allclose(cost[0], [1.0, 3.0, 7.0, 9.0, 9.0, np.inf])
    # the caller's belief and mask are not modified
    assert (b == 255).all() and blocked.sum() == 1


def test_free_start_opens_the_cells_around_the_robot_only():
    cost = np.full((5, 5), np.inf)
    cost[0, 4] = 3.0
    out = free_start(cost, (2, 2), radius_cells=1)
    assert np.isinf(cost).sum() == 24  # input untouched
    assert (out[1:4, 1:4] == 20.0).all()
    assert np.isinf(out).sum() == 25 - 9 - 1 and out[0, 4] == 3.0
    # a corner robot: the patch is clipped to the grid, finite cells keep their cost
    cost[0, 1] = 2.0
    corner = free_start(cost, (0, 0), radius_cells=1)
    assert corner[0, 0] == 20.0 and corner[1, 0] == 20.0 and corner[1, 1] == 20.0
    assert corner[0, 1] == 2.0
    assert np.isinf(corner).sum() == 25 - 4 - 1
    # radius 0: only the robot's own cell
    single = free_start(np.full((3, 3), np.inf), (1, 1), radius_cells=0)
    assert np.isfinite(single).sum() == 1 and single[1, 1] == 20.0


# ---------------------------------------------------------------- Dijkstra


def test_cost_field_gives_metric_path_lengths_on_a_uniform_grid():
    field = cost_field(np.ones((5, 5)), (2, 2), 0.1)
    assert field.start_rc == (2, 2)
    assert field.cumulative[2, 2] == 0.0
    assert field.cumulative[2, 4] == pytest.approx(0.2)  # two straight steps
    assert field.cumulative[4, 4] == pytest.approx(0.2 * math.sqrt(2))  # two diagonal steps
    assert field.cumulative[0, 3] == pytest.approx(0.1 + 0.1 * math.sqrt(2))
    assert field.reachable().all()


def test_cost_field_clamps_a_start_outside_the_grid():
    field = cost_field(np.ones((4, 6)), (-3, 10), 1.0)
    assert field.start_rc == (0, 5)
    assert field.cumulative[0, 5] == 0.0 and field.cumulative[0, 0] == pytest.approx(5.0)


def test_path_goes_through_the_doorway_and_unreachable_goals_give_an_empty_path():
    # 10 × 10 free cells, a wall in column 5 over rows 0–7: the door is rows 8–9.
    b = np.full((10, 10), 255, np.uint8)
    b[:8, 5] = 0
    cost = traversal_costs(b, 0.1, 0.0, clearance_m=0.1)
    field = cost_field(cost, (0, 0), 0.1)
    path = field.path((0, 9))
    assert path.dtype == np.int64 and path.shape[1] == 2
    assert tuple(path[0]) == (0, 0) and tuple(path[-1]) == (0, 9)
    assert path[path[:, 1] == 5, 0].min() >= 8  # crosses column 5 only in the door
    assert np.all(np.abs(np.diff(path, axis=0)).max(axis=1) == 1)  # 8-connected steps
    # close the door: the right half becomes unreachable
    b[8:, 5] = 0
    field = cost_field(traversal_costs(b, 0.1, 0.0, clearance_m=0.1), (0, 0), 0.1)
    assert field.path((0, 9)).shape == (0, 2)
    assert not field.reachable()[:, 6:].any() and field.reachable()[:, :5].all()


# ---------------------------------------------------------------- polylines


def test_simplify_keeps_points_spacing_apart_and_both_ends():
    xs = np.array([0.0, 0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 1.75])
    path = np.stack([xs, np.zeros_like(xs)], axis=1)
    out = simplify_path(path, 0.5)
    # 0.5 away counts as far enough; the end (1.75) is kept although 0.25 from 1.5
    assert out[:, 0].tolist() == [0.0, 0.5, 1.0, 1.5, 1.75]
    two = path[:2]
    assert simplify_path(two, 10.0) is two


def test_densify_inserts_evenly_spaced_points_per_segment():
    path = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 0.5]])
    out = densify_path(path, 0.3)
    # first leg 1 m → ceil(1/0.3) = 4 steps of 0.25; second leg 0.5 m → 2 steps of 0.25
    expected = [[0, 0], [0.25, 0], [0.5, 0], [0.75, 0], [1, 0], [1, 0.25], [1, 0.5]]
    np.testing.assert_allclose(out, expected)
    # a leg exactly spacing long is one step; a zero-length leg repeats its point once
    leg = np.array([[0.0, 0.0], [0.5, 0.0]])
    np.testing.assert_allclose(densify_path(leg, 0.5), leg)
    still = np.array([[1.0, 1.0], [1.0, 1.0]])
    np.testing.assert_allclose(densify_path(still, 0.5), still)
    one = np.array([[2.0, 3.0]])
    assert densify_path(one, 0.1) is one


def test_cells_to_world_gives_cell_centres():
    grid = GridSpec((1.0, 2.0), 0.5, (4, 4))
    np.testing.assert_allclose(cells_to_world(grid, np.array([0, 0])), [[1.25, 2.25]])
    np.testing.assert_allclose(cells_to_world(grid, [[2, 3], [1, 0]]), [[2.75, 3.25], [1.25, 2.75]])


@pytest.mark.parametrize(
    ("a", "expected"),
    [
        (0.0, 0.0),
        (math.pi, -math.pi),
        (-math.pi, -math.pi),
        (1.5 * math.pi, -0.5 * math.pi),
        (-1.5 * math.pi, 0.5 * math.pi),
        (2 * math.pi + 0.1, 0.1),
        (3.0, 3.0),
    ],
)
def test_wrap_angle_to_minus_pi_pi(a, expected):
    assert wrap_angle(a) == pytest.approx(expected)


# ---------------------------------------------------------------- pure pursuit


def straight_path() -> PurePursuit:
    pp = PurePursuit()  # lookahead 0.5, turn in place above 0.9 rad, gain 1.5, tolerance 0.2
    pp.set_path(np.array([[0.0, 0.0], [2.0, 0.0]]))
    return pp


def test_pure_pursuit_without_a_path_stands_still():
    pp = PurePursuit()
    assert not pp.has_path
    assert pp.command((0.0, 0.0, 0.0)) == (0.0, 0.0)
    assert pp.remaining_m(np.zeros(2)) == 0.0


def test_pure_pursuit_resamples_every_5_cm_and_measures_the_rest_of_the_path():
    pp = straight_path()
    assert pp.has_path and len(pp.path) == 41
    assert pp.remaining_m(np.array([0.0, 0.3])) == pytest.approx(2.3)
    single = PurePursuit()
    single.set_path(np.array([1.0, 1.0]))
    assert single.has_path and single.remaining_m(np.array([1.0, 0.0])) == pytest.approx(1.0)


def test_pure_pursuit_drives_straight_at_a_carrot_ahead():
    pp = straight_path()
    assert pp.command((0.0, 0.0, 0.0)) == pytest.approx((1.0, 0.0))


def test_pure_pursuit_steers_towards_the_carrot_with_proportional_gain():
    pp = straight_path()
    linear, angular = pp.command((0.0, 0.0, -0.5))  # carrot (0.5, 0): bearing +0.5 rad
    assert linear == pytest.approx(math.cos(0.5))
    assert angular == pytest.approx(0.75)
    # from (0.5, 0.1) the progress moves to x = 0.5 and the carrot is (1.0, 0), the first point
    # at least 0.5 m away (0.95 is 0.46 m away)
    linear, angular = pp.command((0.5, 0.1, 0.0))
    bearing = math.atan2(-0.1, 0.5)
    assert angular == pytest.approx(1.5 * bearing) and linear == pytest.approx(math.cos(bearing))
    assert pp.remaining_m(np.array([0.5, 0.1])) == pytest.approx(1.6)
    # progress never goes backwards: back at the start, the rest of the path is still 1.5 m
    pp.command((0.0, 0.1, 0.0))
    assert pp.remaining_m(np.array([0.0, 0.1])) == pytest.approx(math.hypot(0.5, 0.1) + 1.5)


def test_pure_pursuit_turns_in_place_on_a_large_bearing_error():
    pp = straight_path()
    assert pp.command((0.0, 0.0, math.pi / 2)) == (0.0, -1.0)  # carrot to the right
    assert pp.command((0.0, 0.0, -math.pi / 2)) == (0.0, 1.0)  # carrot to the left
    # just below the threshold it drives, slowly: linear ≥ 0.2, angular saturated at ±1
    pp = PurePursuit(turn_in_place_rad=1.5)
    pp.set_path(np.array([[0.0, 0.0], [2.0, 0.0]]))
    assert pp.command((0.0, 0.0, -1.45)) == pytest.approx((0.2, 1.0))
    assert pp.command((0.0, 0.0, 1.45)) == pytest.approx((0.2, -1.0))


def test_pure_pursuit_aims_at_the_end_when_the_path_is_shorter_than_the_lookahead():
    pp = PurePursuit()
    pp.set_path(np.array([[0.0, 0.0], [0.4, 0.0]]))
    linear, angular = pp.command((0.0, 0.0, 0.3))  # carrot = end (0.4, 0): bearing −0.3
    assert angular == pytest.approx(-0.45) and linear == pytest.approx(math.cos(0.3))


def test_pure_pursuit_stops_within_the_goal_tolerance_and_drops_the_path():
    pp = straight_path()
    assert pp.command((1.85, 0.0, 0.0)) == (0.0, 0.0)
    assert not pp.has_path
    pp = straight_path()
    assert pp.command((2.0, 0.2, 0.0)) == (0.0, 0.0)  # exactly at the tolerance
    pp = straight_path()
    assert pp.command((1.75, 0.0, 0.0)) != (0.0, 0.0) and pp.has_path


@pytest.mark.parametrize(
    ("linear", "angular", "action"),
    [
        (1.0, 0.0, 0),
        (1.0, 0.35, 0),
        (1.0, -0.35, 0),
        (1.0, 0.36, 1),
        (1.0, -0.36, 2),
        (0.0, 0.1, 1),
        (0.0, 0.0, 2),
        (-0.5, -0.1, 2),
        (0.01, 0.0, 0),
    ],
)
def test_to_discrete_forward_inside_the_deadband_else_turn(linear, angular, action):
    assert to_discrete(linear, angular) == action


# ---------------------------------------------------------------- disks and contacts


@pytest.mark.parametrize(("radius", "count"), [(0.5, 1), (1.0, 5), (1.5, 9), (2.0, 13)])
def test_disk_offsets_count_the_lattice_points_of_a_disk(radius, count):
    off = disk_offsets(radius)
    assert off.shape == (count, 2)
    assert (off**2).sum(axis=1).max() <= radius**2
    assert len({tuple(o) for o in off}) == count and [0, 0] in off.tolist()


def test_disk_cells_are_clipped_to_the_grid():
    rows, cols = disk_cells((5, 5), (0, 0), 1.0)
    assert sorted(zip(rows.tolist(), cols.tolist(), strict=True)) == [(0, 0), (0, 1), (1, 0)]
    rows, cols = disk_cells((5, 5), (4, 4), 1.0)
    assert sorted(zip(rows.tolist(), cols.tolist(), strict=True)) == [(3, 4), (4, 3), (4, 4)]
    assert len(disk_cells((9, 9), (4, 4), 1.5)[0]) == 9
    assert len(disk_cells((9, 9), (4, 4), 1.2)[0]) == 5  # radius rounds up to 2 for the box
    assert len(disk_cells((9, 9), (4, 4), 2.0)[0]) == 13


def test_mark_disk_sets_the_disk_in_place():
    mask = np.zeros((6, 6), bool)
    mark_disk(mask, (5, 0), 1.0)
    assert mask.sum() == 3 and mask[5, 0] and mask[4, 0] and mask[5, 1]


def test_mark_contact_marks_the_cell_just_ahead_of_the_bumper():
    grid = GridSpec((0.0, 0.0), 0.1, (20, 20))
    mask = np.zeros(grid.shape, bool)
    # robot at (1.0, 1.05) facing +x, radius 0.2: contact 0.25 m ahead at (1.25, 1.05),
    # cell (row 10, col 12) and its 4 neighbours
    mark_contact(mask, grid, (1.0, 1.05, 0.0), 0.2)
    assert mask.sum() == 5 and mask[10, 12] and mask[10, 11] and mask[10, 13] and mask[9, 12]
    # facing +y from (1.05, 1.07): contact (1.05, 1.32), cell (13, 10)
    mask[:] = False
    mark_contact(mask, grid, (1.05, 1.07, math.pi / 2), 0.2)
    assert mask.sum() == 5 and mask[13, 10] and mask[12, 10] and mask[14, 10]


# ---------------------------------------------------------------- from the mutation review


def test_default_unknown_cost_is_one_and_a_half():
    assert traversal_costs(np.array([[127, 255]], np.uint8), 0.1, 0.2).tolist() == [[1.5, 1.0]]


def test_free_start_default_radius_edges_and_the_robots_own_finite_cell():
    cost = np.full((5, 5), np.inf)
    out = free_start(cost, (2, 2))  # default: one cell around the robot
    assert np.isfinite(out).sum() == 9
    top = free_start(cost, (0, 2), radius_cells=1)  # on the top edge: rows 0-1, columns 1-3
    assert np.isfinite(top).sum() == 6 and np.isfinite(top[0, 1:4]).all()
    ones = free_start(np.ones((3, 3)), (1, 1))
    assert (ones == 1.0).all()  # passable cells, the robot's included, keep their cost
    # a start just outside the grid frees the border cells beside it, nothing else
    below = free_start(cost, (5, 2), radius_cells=1)
    assert np.isfinite(below).sum() == 3 and np.isfinite(below[4, 1:4]).all()
    right = free_start(cost, (2, 5), radius_cells=1)
    assert np.isfinite(right).sum() == 3 and np.isfinite(right[1:4, 4]).all()


def test_cost_field_clamps_a_start_below_and_right_of_the_grid_and_keeps_the_resolution():
    field = cost_field(np.ones((4, 6)), (10, -2), 0.25)
    assert field.start_rc == (3, 0) and field.resolution_m == 0.25
    assert field.cumulative[3, 5] == pytest.approx(5 * 0.25)


def test_unreachable_path_is_an_empty_int_array():
    cost = np.ones((3, 3))
    cost[:, 1] = np.inf
    path = cost_field(cost, (0, 0), 1.0).path((0, 2))
    assert path.shape == (0, 2) and path.dtype == np.int64


def test_simplify_thins_three_points_and_considers_the_second_point():
    three = np.array([[0.0, 0.0], [0.1, 0.0], [1.0, 0.0]])
    assert simplify_path(three, 0.5)[:, 0].tolist() == [0.0, 1.0]
    four = np.array([[0.0, 0.0], [0.625, 0.0], [0.75, 0.0], [1.5, 0.0]])
    assert simplify_path(four, 0.5)[:, 0].tolist() == [0.0, 0.625, 1.5]


def test_remaining_m_counts_the_last_leg():
    pp = PurePursuit()
    pp.set_path(np.array([[0.0, 0.0], [0.05, 0.0]]))  # two points after resampling
    assert len(pp.path) == 2
    assert pp.remaining_m(np.array([0.0, 0.1])) == pytest.approx(0.15)


def test_carrot_is_the_path_end_when_every_point_is_within_the_lookahead():
    pp = PurePursuit()
    pp.set_path(np.array([[0.0, 0.0], [0.4, 0.0]]))
    linear, angular = pp.command((0.0, 0.1, 0.0))  # end (0.4, 0) is 0.41 m away
    bearing = math.atan2(-0.1, 0.4)
    assert angular == pytest.approx(1.5 * bearing) and linear == pytest.approx(math.cos(bearing))


def test_a_point_exactly_at_the_lookahead_is_the_carrot():
    pp = PurePursuit()  # lookahead 0.5 m
    pp.set_path(np.array([[0.0, 0.0], [0.5, 0.0], [0.5, 1.0]]))  # corner exactly 0.5 m ahead
    assert pp.command((0.0, 0.0, 0.0)) == pytest.approx((1.0, 0.0))


def test_a_bearing_equal_to_the_turn_threshold_still_drives():
    pp = PurePursuit(turn_in_place_rad=wrap_angle(1.0))
    pp.set_path(np.array([[0.0, 0.0], [2.0, 0.0]]))
    linear, angular = pp.command((0.0, 0.0, -1.0))  # bearing to the carrot: +1 rad
    assert linear == pytest.approx(math.cos(1.0)) and angular == 1.0


@pytest.mark.parametrize("seed", range(4))
def test_cost_field_matches_scikit_image_mcp_and_its_paths_add_up(seed):
    """The compiled Dijkstra gives MCP_Geometric's costs; each traced path costs exactly that."""
    from skimage.graph import MCP_Geometric

    rng = np.random.default_rng(seed)
    shape = (30 + 7 * seed, 45)
    cost = np.where(rng.random(shape) < 0.25, np.inf, 1.0 + 3.0 * rng.random(shape))
    start = (shape[0] // 2, shape[1] // 3)
    cost[start] = 1.0
    field = cost_field(cost, start, resolution_m=0.1)
    reference, _ = MCP_Geometric(cost, fully_connected=True).find_costs([start])
    reachable = np.isfinite(reference)
    assert np.array_equal(field.reachable(), reachable)
    assert field.cumulative[reachable] == pytest.approx(0.1 * reference[reachable], rel=1e-12)
    goals = np.argwhere(reachable)[rng.choice(reachable.sum(), 20)]
    for goal in map(tuple, goals):
        path = field.path(goal)
        assert tuple(path[0]) == start and tuple(path[-1]) == goal
        steps = np.diff(path, axis=0)
        assert np.abs(steps).max(initial=0) <= 1 and (np.abs(steps).sum(axis=1) > 0).all()
        length = np.where(np.abs(steps).sum(axis=1) == 2, np.sqrt(2.0), 1.0)
        mean_cost = 0.5 * (cost[tuple(path[:-1].T)] + cost[tuple(path[1:].T)])
        assert 0.1 * float((length * mean_cost).sum()) == pytest.approx(field.cumulative[goal])
    blocked = tuple(np.argwhere(~reachable)[0])
    assert len(field.path(blocked)) == 0


def test_cost_field_refuses_cells_cheaper_than_one():
    cost = np.ones((5, 5))
    cost[2, 2] = 0.5
    with pytest.raises(ValueError, match="cell costs must be >= 1"):
        cost_field(cost, (0, 0), 0.1)


def test_a_bounded_cost_field_is_exact_below_its_bound_and_inf_beyond():
    rng = np.random.default_rng(1)
    cost = np.where(rng.random((80, 90)) < 0.15, np.inf, 1.0 + 2.0 * rng.random((80, 90)))
    cost[40, 40] = 1.0
    full = cost_field(cost, (40, 40), 0.1)
    part = cost_field(cost, (40, 40), 0.1, max_cost_m=1.5)
    assert full.complete and not part.complete
    known = np.isfinite(part.cumulative)
    assert np.array_equal(part.cumulative[known], full.cumulative[known])  # exact where known
    assert known[full.cumulative < 1.5].all()  # everything cheaper than the bound is known
    assert (full.cumulative[~known] > 1.5).all()
    goal = tuple(np.argwhere(known & (part.cumulative > 1.0))[0])
    path = part.path(goal)
    assert tuple(path[0]) == (40, 40) and tuple(path[-1]) == goal
    assert known[tuple(path.T)].all()  # a settled cell's path runs through settled cells


def test_cost_field_paths_are_mcp_paths_even_where_costs_tie():
    """On a uniform grid most goals have many equal-cost paths; the compiled search picks the
    one scikit-image's heap-ordered MCP picks (all but the rare ties between equal costs)."""
    from skimage.graph import MCP_Geometric

    cost = np.ones((21, 31))
    cost[5:15, 12] = np.inf
    start = (10, 15)
    field = cost_field(cost, start, 0.1)
    mcp = MCP_Geometric(cost, fully_connected=True)
    mcp.find_costs([start])
    goals = list(map(tuple, np.argwhere(field.reachable())))
    same = sum(np.array_equal(field.path(g), np.asarray(mcp.traceback(g))) for g in goals)
    assert same >= 0.99 * len(goals)


@pytest.mark.parametrize("start", [(3, 4), (100, 60), (196, 110)])
def test_a_bounded_search_in_a_large_grid_is_the_full_searchs_prefix(start):
    """The bounded search scans and cleans only a window around the start: on a grid much
    larger than the window (and with the window cut by the grid's edges) its settled cells have
    the full search's costs and predecessors, and every other cell is ``inf`` / -1."""
    rng = np.random.default_rng(7)
    cost = np.where(rng.random((200, 115)) < 0.1, np.inf, 1.0 + 3.0 * rng.random((200, 115)))
    cost[start] = 1.0
    full = cost_field(cost, start, 0.1)
    part = cost_field(cost, start, 0.1, max_cost_m=1.2)
    known = np.isfinite(part.cumulative)
    assert 20 < known.sum() < 0.05 * cost.size
    assert np.array_equal(part.cumulative[known], full.cumulative[known])
    assert np.array_equal(part.predecessor[known.ravel()], full.predecessor[known.ravel()])
    assert (part.predecessor[~known.ravel()] == -1).all()
    assert known[full.cumulative <= 1.2].all()


def test_a_bounded_search_sees_expensive_cells_at_its_edge():
    """Costly cells just inside the bound's reach must size the bucket ring: a search bounded at
    1 m among cells of cost 40 one metre out gives the full search's costs where it settles."""
    cost = np.ones((60, 60))
    cost[:, 41:43] = 40.0  # a costly band 11-12 cells east of the start
    full = cost_field(cost, (30, 30), 0.1)
    part = cost_field(cost, (30, 30), 0.1, max_cost_m=1.0)
    known = np.isfinite(part.cumulative)
    assert np.array_equal(part.cumulative[known], full.cumulative[known])


def test_a_path_is_traced_back_along_the_predecessors_and_a_cycle_is_an_error():
    from sfw_gym.navigation.planning import _trace_back

    pred = np.array([-1, 0, 1, 2, 1], np.int64)  # 0 is the start; 4 branches off 1
    assert _trace_back(pred, 3).tolist() == [0, 1, 2, 3]
    assert _trace_back(pred, 4).tolist() == [0, 1, 4]
    assert _trace_back(pred, 0).tolist() == [0]
    with pytest.raises(ValueError, match="cycle"):
        _trace_back(np.array([1, 0], np.int64), 0)  # a corrupted search: 0 -> 1 -> 0 -> ...
