"""Sparse inverse k-visibility: hand-computable updates, two rooms, bookkeeping, bad input."""

from __future__ import annotations

import itertools
import math
import pickle
from dataclasses import replace

import numpy as np
import pytest

from sfw_gym.core.errors import ConfigError
from sfw_gym.mapping import (
    GridSpec,
    MapperConfig,
    SparseInverseKVisibility,
    belief_classes,
    ray_cells,
)
from sfw_gym.mapping.metrics import interior_wall_recall, wall_precision

K0 = 20.0 - 40.2  # RSSI at 1 m with no wall: P_tx - PL(1 m)
WALL_DB = 10.0
R = 0.17


# -- a synthetic world from plain numpy -------------------------------------------------------
def crossings(points: np.ndarray, router, walls) -> np.ndarray:
    """Number of wall segments properly crossed by each segment point -> router."""

    def orient(ax, ay, bx, by, cx, cy):
        return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)

    px, py = points[:, 0], points[:, 1]
    rx, ry = router
    k = np.zeros(len(points), np.int64)
    for x0, y0, x1, y1 in walls:
        d1 = orient(x0, y0, x1, y1, px, py)
        d2 = orient(x0, y0, x1, y1, rx, ry)
        d3 = orient(px, py, rx, ry, x0, y0)
        d4 = orient(px, py, rx, ry, x1, y1)
        k += ((d1 * d2 < 0) & (d3 * d4 < 0)).astype(np.int64)
    return k


def rssi_at(points, router, walls, rng, noise_db=2.0) -> np.ndarray:
    d = np.maximum(np.hypot(*(points - np.asarray(router)).T), 0.1)
    level = K0 - 20.0 * np.log10(d) - WALL_DB * crossings(points, router, walls)
    return np.round(level + rng.normal(0.0, noise_db, len(points)))


def polyline(waypoints, step=0.05) -> np.ndarray:
    out = []
    for a, b in itertools.pairwise(waypoints):
        n = max(1, math.ceil(math.dist(a, b) / step))
        t = np.arange(n)[:, None] / n
        out.append(np.asarray(a) + t * (np.asarray(b) - np.asarray(a)))
    out.append(np.asarray([waypoints[-1]]))
    return np.concatenate(out)


def lawnmower(x0, x1, ys) -> list:
    pts = []
    for i, y in enumerate(ys):
        pts += [(x0, y), (x1, y)] if i % 2 == 0 else [(x1, y), (x0, y)]
    return pts


def truth_map(grid: GridSpec, width, height, walls_cells) -> np.ndarray:
    xs, ys = grid.cell_centres()
    h = 0.05
    inside = (xs > -h) & (xs < width + h) & (ys > -h) & (ys < height + h)
    outer = inside & ((xs < h) | (xs > width - h) | (ys < h) | (ys > height - h))
    out = np.full(grid.shape, 127, np.uint8)
    out[inside] = 255
    out[outer | walls_cells(xs, ys)] = 0
    return out


def run(mapper, traj, rssi):
    for p, r in zip(traj, rssi, strict=True):
        mapper.update(p, r)
    return mapper


# -- the two-room test --------------------------------------------------------------------------
W, H, WALL_X, DOOR_Y = 6.0, 4.0, 3.0, 3.0
TWO_ROOM_WALLS = [(WALL_X, 0.0, WALL_X, DOOR_Y)]


def two_rooms(grid):
    def inner(xs, ys):
        return (np.abs(xs - WALL_X) < 0.05) & (ys < DOOR_Y)

    return truth_map(grid, W, H, inner)


def two_room_survey() -> np.ndarray:
    c = R + 0.05
    ys = np.arange(c, H - c + 1e-9, 0.3)
    left = lawnmower(c, WALL_X - 0.05 - c, ys)
    door = [(WALL_X - 0.05 - c, 3.5), (WALL_X + 0.05 + c, 3.5)]
    right = lawnmower(WALL_X + 0.05 + c, W - c, ys[::-1])
    return polyline([*left, *door, *right])


@pytest.fixture(scope="module")
def two_room_result():
    grid = GridSpec.covering((0.0, 0.0, W, H), 0.05, margin_m=0.1)
    router = (1.0, 1.5)
    traj = two_room_survey()
    rssi = rssi_at(traj, router, TWO_ROOM_WALLS, np.random.default_rng(0))[:, None]
    mapper = run(SparseInverseKVisibility(grid, [router]), traj, rssi)
    return grid, mapper, two_rooms(grid)


def test_two_rooms_wall_found_within_two_cells(two_room_result):
    grid, mapper, truth = two_room_result
    est = mapper.occupancy_u8
    assert interior_wall_recall(est, truth, tolerance_cells=2) >= 0.7
    assert wall_precision(est, truth, tolerance_cells=2) >= 0.9
    wall = belief_classes(est)[1]
    xs, _ = grid.cell_centres()
    assert wall[np.abs(xs - WALL_X) <= 0.15].sum() >= 0.7 * DOOR_Y / 0.05  # a wall, not a dot


def test_two_rooms_both_interiors_free(two_room_result):
    grid, mapper, _ = two_room_result
    free = belief_classes(mapper.occupancy_u8)[0]
    xs, ys = grid.cell_centres()
    core = (ys > 0.4) & (ys < H - 0.4)
    for lo, hi in ((0.4, WALL_X - 0.4), (WALL_X + 0.4, W - 0.4)):
        room = core & (xs > lo) & (xs < hi)
        assert free[room].mean() >= 0.95


def test_pure_line_of_sight_gives_no_wall():
    grid = GridSpec.covering((0.0, 0.0, 4.0, 4.0), 0.05, margin_m=0.1)
    router = (1.3, 2.2)
    c = R + 0.05
    traj = polyline(lawnmower(c, 4.0 - c, np.arange(c, 4.0 - c, 0.4)))
    rssi = rssi_at(traj, router, [], np.random.default_rng(1))[:, None]
    for policy in ("strongest", "all"):
        mapper = run(
            SparseInverseKVisibility(grid, [router], MapperConfig(router_policy=policy)), traj, rssi
        )
        free, wall, _ = belief_classes(mapper.occupancy_u8)
        assert not wall.any()
        xs, ys = grid.cell_centres()
        core = (xs > 0.3) & (xs < 3.7) & (ys > 0.3) & (ys < 3.7)
        assert free[core].mean() > 0.95


# -- hand-computable single updates ---------------------------------------------------------------
GRID = GridSpec((0.0, 0.0), 0.1, (20, 60))
ROUTER = (0.25, 1.05)
# Calibrated, unfiltered: thresholds are K0 - 5, K0 - 15, K0 - 25 until the first fit.
EXACT = MapperConfig(filter_window=1, k0_level_dbm=K0, robot_radius_m=0.0)


def rssi_k(p, k, router=ROUTER) -> list[float]:
    """The RSSI that reads as exactly k at p."""
    return [K0 - 20.0 * math.log10(max(math.dist(p, router), 1.0)) - WALL_DB * k]


def logit(p):
    return math.log(p / (1.0 - p))


def test_rule_2_first_reading_frees_the_ray_exactly():
    m = SparseInverseKVisibility(GRID, [ROUTER], replace(EXACT, robot_radius_m=0.12))
    p = (4.05, 1.05)
    gain = m.update(p, rssi_k(p, 0))
    assert m.last_k.tolist() == [0]
    lo = m.log_odds
    ray = [tuple(c) for c in ray_cells(GRID, ROUTER, p).tolist()]
    assert ray[0] == (10, 2) and ray[-1] == (10, 40)
    assert all(lo[c] == pytest.approx(-0.4) for c in ray[:-2])  # Delta k = 0: free
    assert lo[10, 40] == pytest.approx(-1.0)  # robot cell: footprint only
    assert lo[10, 39] == pytest.approx(-1.4)  # footprint (centre 0.1 m away) and ray
    assert lo[9, 40] == lo[11, 40] == lo[10, 41] == pytest.approx(-1.0)
    assert lo[11, 41] == 0.0  # centre 0.141 m away: outside the 0.12 m footprint
    touched = lo != 0.0
    assert touched.sum() == len(ray) + 3
    h = lambda q: -(q * math.log2(q) + (1 - q) * math.log2(1 - q))  # noqa: E731
    p_occ = 1.0 / (1.0 + np.exp(-lo[touched].astype(np.float64)))
    assert gain == pytest.approx(sum(1.0 - h(q) for q in p_occ))
    assert m.entropy_bits == pytest.approx(20 * 60 - gain)


def test_delta_k_1_puts_a_peak_at_the_middle_of_the_piece():
    m = SparseInverseKVisibility(GRID, [ROUTER], EXACT)
    a, b = (2.05, 1.05), (5.05, 1.05)  # on one ray from the router
    m.update(a, rssi_k(a, 0))
    m.update(b, rssi_k(b, 1))  # one wall between a and b
    lo = m.log_odds[10]
    assert (lo[3:20] < 0).all()  # router .. a: Delta k = 0, free
    # The wall can be in cells 21..49 (2.1 .. 5.0 m): L = 2.9 m, peak in the middle (3.55 m),
    # of height logit(0.5 + 0.3 * 0.5 / 2.9) (Eq. 6, flattened by length).
    assert int(np.argmax(lo)) in (35, 36)
    assert lo.max() == pytest.approx(logit(0.5 + 0.3 * 0.5 / 2.9), rel=1e-3)
    sigma = 0.15 * 2.9
    g = math.exp(-(0.5**2) / (2 * sigma**2))  # 0.5 m from the peak
    assert lo[30] == pytest.approx(logit(0.5 + 0.3 * 0.5 / 2.9 * g), rel=0.05)


def test_delta_k_2_puts_two_peaks():
    m = SparseInverseKVisibility(GRID, [ROUTER], EXACT)
    a, b = (1.05, 1.05), (5.05, 1.05)
    m.update(a, rssi_k(a, 0))
    m.update(b, rssi_k(b, 2))
    lo = m.log_odds[10, 11:50]
    peaks = [11 + i for i in range(1, len(lo) - 1) if lo[i] >= lo[i - 1] and lo[i] > lo[i + 1]]
    # cells 11..49 (1.1 .. 5.0 m) cut in two: peaks at 2.075 and 4.025 m
    assert peaks == [20, 40]


def test_decreasing_k_is_inconsistent_and_skipped():
    m = SparseInverseKVisibility(GRID, [ROUTER], EXACT)
    a, b = (2.05, 1.05), (5.05, 1.05)
    m.update(a, rssi_k(a, 1))  # one wall between the router and a
    m.update(b, rssi_k(b, 0))  # ... yet none between the router and b: k fell along the ray
    lo = m.log_odds[10]
    assert (lo[21:50] == 0).all()  # the piece a..b is skipped
    assert lo[3:20].max() > 0  # router..a still holds its wall evidence


def test_equal_readings_at_max_k_are_not_free_evidence():
    # Both ends read K = 1 ("one wall or more"): the walls between them are unknown.
    a, b = (2.05, 1.05), (5.05, 1.05)
    for max_k, expect_free in ((3, True), (1, False)):
        m = SparseInverseKVisibility(GRID, [ROUTER], replace(EXACT, max_k=max_k))
        m.update(a, rssi_k(a, 1))
        m.update(b, rssi_k(b, 1))
        lo = m.log_odds[10]
        assert m.last_k.tolist() == [1]
        assert (lo[21:50] < 0).all() if expect_free else (lo[21:50] == 0).all()
        assert lo[3:20].max() > 0  # router .. a: one wall either way


def test_ray_past_the_robot_is_cut_at_every_earlier_point():
    # Three points on one ray from the router, all k = 0, visited far to near (1.5 and 2 m
    # apart: never joined into one trajectory segment).
    far, mid, near = (5.55, 1.05), (4.05, 1.05), (2.05, 1.05)
    out = {}
    for extend in (True, False):
        m = SparseInverseKVisibility(GRID, [ROUTER], replace(EXACT, extend_past_robot=extend))
        for p in (far, mid, near):
            m.update(p, rssi_k(p, 0))
        out[extend] = m.log_odds[10]
    lo = out[True]
    # every piece of the line is freed by every later reading on it: far's own ray, mid's ray
    # extended past mid to far, near's ray extended past near to mid and on to far
    assert lo[2:20] == pytest.approx(np.full(18, -1.2))
    assert lo[21:40] == pytest.approx(np.full(19, -1.2))
    assert lo[41:55] == pytest.approx(np.full(14, -1.2))
    # the points' own cells: footprint, plus the rays of the readings taken before, beyond them
    assert lo[[20, 40, 55]] == pytest.approx([-1.8, -1.4, -1.0])
    # without the extension only the stretch router -> robot is updated
    assert out[False][41:55] == pytest.approx(np.full(14, -0.4))
    assert out[False][21:40] == pytest.approx(np.full(19, -0.8))


def test_bump_marks_the_contact_cell():
    m = SparseInverseKVisibility(GRID, [ROUTER], replace(EXACT, robot_radius_m=0.17))
    m.update((3.05, 1.05), [-100.0], bumped=True, heading_rad=0.0)
    contact = tuple(GRID.world_to_cell((3.05 + 0.17 + 0.05, 1.05)))
    assert contact == (10, 32)
    assert m.log_odds[contact] == pytest.approx(3.0)
    assert m.occupancy_u8[contact] == int(255 / (1 + math.exp(3.0)))
    # without a heading a bump marks nothing
    m2 = SparseInverseKVisibility(GRID, [ROUTER], replace(EXACT, robot_radius_m=0.17))
    m2.update((3.05, 1.05), [-100.0], bumped=True)
    assert (m2.log_odds <= 0).all()


def test_not_heard_updates_only_the_footprint():
    m = SparseInverseKVisibility(GRID, [ROUTER, (5.0, 0.5)], replace(EXACT, robot_radius_m=0.12))
    m.update((3.05, 1.05), [-100.0, -100.0])
    assert (m.log_odds != 0).sum() == 5
    assert m.last_k.tolist() == [-1, -1]
    assert m.last_routers.size == 0


# -- bookkeeping ---------------------------------------------------------------------------------
def test_entropy_changes_and_views_stay_consistent(two_room_result):
    grid, mapper, _ = two_room_result
    assert mapper.entropy_bits == pytest.approx(mapper.recompute_entropy_bits(), rel=1e-9)
    fresh = SparseInverseKVisibility(grid, mapper.routers_xy)
    traj = two_room_survey()[:400]
    rssi = rssi_at(traj, mapper.routers_xy[0], TWO_ROOM_WALLS, np.random.default_rng(3))
    total = 0.0
    for p, r in zip(traj, rssi, strict=True):
        free0, wall0, _ = belief_classes(fresh.occupancy_u8)
        cls0 = wall0 * 2 + free0
        total += fresh.update(p, [r])
        free1, wall1, _ = belief_classes(fresh.occupancy_u8)
        cls1 = wall1 * 2 + free1
        assert set(fresh.last_changed_cells.tolist()) == set(np.flatnonzero(cls1 != cls0))
    assert total == pytest.approx(grid.shape[0] * grid.shape[1] - fresh.entropy_bits)
    assert np.array_equal(fresh.classified, belief_classes(fresh.occupancy_u8)[1] | free1)
    p = fresh.probability
    assert p.dtype == np.float32
    assert np.allclose(p, 1 / (1 + np.exp(-fresh.log_odds.astype(np.float64))), atol=1e-6)
    assert np.array_equal(fresh.occupancy_u8, np.floor(255 * (1 - p.astype(np.float64))).clip(0))
    for view in (fresh.occupancy_u8, fresh.log_odds, fresh.classified):
        with pytest.raises(ValueError):
            view[0, 0] = 1
    fresh.reset()
    assert (fresh.occupancy_u8 == 127).all() and fresh.entropy_bits == grid.shape[0] * grid.shape[1]


def test_pickle_round_trip_continues_identically():
    m = SparseInverseKVisibility(GRID, [ROUTER], EXACT)
    path = [(x, 1.05 + 0.3 * math.sin(x)) for x in np.arange(0.5, 5.5, 0.05)]
    for p in path[:40]:
        m.update(p, rssi_k(p, 0))
    clone = pickle.loads(pickle.dumps(m))
    for p in path[40:]:
        k = 1 if p[0] > 3.0 else 0
        assert m.update(p, rssi_k(p, k)) == clone.update(p, rssi_k(p, k))
    assert np.array_equal(m.occupancy_u8, clone.occupancy_u8)
    assert np.array_equal(m.classified, clone.classified)
    assert np.array_equal(m.log_odds, clone.log_odds)
    assert m.entropy_bits == clone.entropy_bits
    assert clone.occupancy_u8.base is not None and not clone.occupancy_u8.flags.writeable


def test_outer_bounds_cells_never_change():
    cfg = replace(EXACT, outer_bounds_m=(0.0, 0.0, 3.0, 2.0), robot_radius_m=0.17)
    m = SparseInverseKVisibility(GRID, [ROUTER], cfg)
    assert m.entropy_bits == 30 * 20
    for x in np.arange(0.3, 5.5, 0.05):
        m.update((x, 1.05), [-40.0])
    xs, _ = GRID.cell_centres()
    assert (m.log_odds[xs > 3.0] == 0).all() and (m.log_odds[xs < 3.0] != 0).any()
    assert m.entropy_bits == pytest.approx(m.recompute_entropy_bits())


def test_router_policy_all_uses_every_heard_router():
    routers = [ROUTER, (5.5, 0.5), (3.0, 1.9)]
    for policy, expected in (("strongest", [2]), ("all", [0, 2])):
        m = SparseInverseKVisibility(GRID, routers, replace(EXACT, router_policy=policy))
        m.update((3.05, 1.05), [-45.0, -100.0, -30.0])
        assert m.last_routers.tolist() == expected


# -- bad input -----------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("position", "rssi", "kwargs", "match"),
    [
        ((np.nan, 1.0), [-40.0], {}, "position_xy must be two finite numbers"),
        ((1.0, 1.0, 1.0), [-40.0], {}, "position_xy must be two finite numbers"),
        ((1.0,), [-40.0], {}, "position_xy"),
        ((6.0, 1.0), [-40.0], {}, "outside"),  # the upper edges are outside
        ((1.0, 2.0), [-40.0], {}, "outside"),
        ((7.0, 1.0), [-40.0], {}, "outside"),
        ((-0.01, 1.0), [-40.0], {}, "outside"),
        ((1.0, 1.0), [np.nan], {}, "rssi_dbm"),
        ((1.0, 1.0), [-40.0, -50.0], {}, "rssi_dbm"),
        ((1.0, 1.0), ["loud"], {}, "rssi_dbm"),
        ((1.0, 1.0), [-40.0], {"bumped": True, "heading_rad": math.inf}, "heading_rad"),
    ],
)
def test_bad_input_raises_and_leaves_the_map_untouched(position, rssi, kwargs, match):
    m = SparseInverseKVisibility(GRID, [ROUTER], EXACT)
    m.update((2.0, 1.0), [-40.0])
    before = (m.log_odds.copy(), m.entropy_bits, m.n_updates, m.k_estimator.n_samples.copy())
    with pytest.raises(ConfigError, match=match):
        m.update(position, rssi, **kwargs)
    assert np.array_equal(m.log_odds, before[0])
    assert m.entropy_bits == before[1] and m.n_updates == before[2]
    assert np.array_equal(m.k_estimator.n_samples, before[3])


def test_bad_construction_raises():
    with pytest.raises(ConfigError, match="routers_xy"):
        SparseInverseKVisibility(GRID, [1.0, 2.0])
    with pytest.raises(ConfigError, match="routers_xy"):
        SparseInverseKVisibility(GRID, [[np.nan, 2.0]])
    with pytest.raises(ConfigError, match="grid"):
        SparseInverseKVisibility((0, 0, 1, 1), [[1.0, 2.0]])
    with pytest.raises(ConfigError, match="config"):
        SparseInverseKVisibility(GRID, [[1.0, 2.0]], {"max_k": 3})


def test_bad_construction_messages_name_the_problem():
    with pytest.raises(ConfigError, match="grid must be a GridSpec, got tuple"):
        SparseInverseKVisibility((0, 0, 1, 1), [[1.0, 2.0]])
    with pytest.raises(ConfigError, match="config must be a MapperConfig, got dict"):
        SparseInverseKVisibility(GRID, [[1.0, 2.0]], {"max_k": 3})
    for bad in (np.zeros((1, 3)), np.zeros((0, 2))):  # three coordinates; no router
        with pytest.raises(ConfigError, match=r"routers_xy must have shape \(R, 2\) with R >= 1"):
            SparseInverseKVisibility(GRID, bad)


def test_routers_are_stored_as_read_only_float_metres():
    routers = [[1, 2], [3, 0]]
    m = SparseInverseKVisibility(GRID, routers, EXACT)
    assert m.routers_xy.dtype == np.float64 and m.routers_xy.tolist() == [[1.0, 2.0], [3.0, 0.0]]
    with pytest.raises(ValueError):  # the mapper's router geometry cannot drift from the array
        m.routers_xy[0, 0] = 5.0


def test_origin_corner_is_inside_and_x_y_use_their_own_origin():
    # origin x != y: a swapped origin coordinate would put the robot in another cell
    grid = GridSpec((-1.0, 2.0), 0.5, (4, 6))
    m = SparseInverseKVisibility(grid, [(0.0, 0.0)], replace(EXACT, robot_radius_m=0.0))
    m.update((-1.0, 2.0), [-100.0])  # the lower-left corner is inside the grid
    assert m.log_odds[0, 0] == pytest.approx(-1.0)  # the footprint of a not-heard reading
    m.reset()
    m.update((0.3, 2.6), [-100.0])  # cell (row 1, col 2)
    assert m.log_odds[1, 2] == pytest.approx(-1.0) and (m.log_odds != 0).sum() == 1


def test_outer_bounds_include_cell_centres_on_the_bound():
    grid = GridSpec((0.0, 0.0), 0.5, (4, 6))  # centres at 0.25, 0.75, 1.25, ...
    cfg = replace(EXACT, outer_bounds_m=(0.25, 0.25, 1.25, 0.75))
    m = SparseInverseKVisibility(grid, [(0.0, 0.0)], cfg)
    assert m.entropy_bits == 3 * 2  # columns 0-2, rows 0-1: 1 bit each
    assert m.recompute_entropy_bits() == pytest.approx(6.0)


def test_policy_all_frees_the_ray_of_every_heard_router_and_strongest_only_one():
    near = (3.0, 1.9)  # 0.85 m from the robot: the strongest
    p = (3.05, 1.05)
    rssi = rssi_k(p, 0) + rssi_k(p, 0, router=near)
    on_far_ray = tuple(GRID.world_to_cell((1.55, 1.05)))  # on the ray to ROUTER only
    on_near_ray = tuple(GRID.world_to_cell((3.0, 1.75)))
    for policy, far_freed in (("strongest", False), ("all", True)):
        m = SparseInverseKVisibility(GRID, [ROUTER, near], replace(EXACT, router_policy=policy))
        m.update(p, rssi)
        assert m.log_odds[on_near_ray] == pytest.approx(-0.4)
        assert m.log_odds[on_far_ray] == pytest.approx(-0.4 if far_freed else 0.0)


def test_update_counts_and_reset_gives_a_fresh_mapper():
    path = [(x, 0.25) for x in np.arange(0.15, 2.0, 0.05)]
    readings = [rssi_k(q, 0 if q[0] < 1.0 else 1) for q in path]
    fresh = SparseInverseKVisibility(GRID, [ROUTER], EXACT)
    used = SparseInverseKVisibility(GRID, [ROUTER], EXACT)
    for x in np.arange(3.0, 5.0, 0.1):  # another history, far away
        used.update((x, 1.55), rssi_k((x, 1.55), 1))
    assert used.n_updates == 20
    used.reset()
    assert used.n_updates == 0 and used.last_changed_cells.size == 0
    for q, r in zip(path, readings, strict=True):
        assert used.update(q, r) == fresh.update(q, r)
    assert used.n_updates == fresh.n_updates == len(path)
    assert np.array_equal(used.log_odds, fresh.log_odds)
    assert used.entropy_bits == fresh.entropy_bits


def test_a_heading_without_bumped_marks_no_wall():
    m = SparseInverseKVisibility(GRID, [ROUTER], replace(EXACT, robot_radius_m=0.17))
    m.update((3.05, 1.05), [-100.0], heading_rad=0.0)  # bumped defaults to False
    assert (m.log_odds <= 0).all()


def test_public_views_have_the_documented_dtypes():
    m = SparseInverseKVisibility(GRID, [ROUTER], EXACT)
    m.update((3.05, 1.05), rssi_k((3.05, 1.05), 0))
    assert m.log_odds.dtype == np.float32 and m.log_odds.shape == GRID.shape
    assert m.occupancy_u8.dtype == np.uint8 and m.classified.dtype == np.bool_
    assert m.probability.dtype == np.float32
    changed = m.last_changed_cells
    assert changed.dtype == np.int64 and changed.size > 0
    assert m.classified.ravel()[changed].all()  # unknown -> free: every change is a new class


def test_log_odds_stop_at_their_clamps_and_the_entropy_follows():
    """Bumps add +3 to the contact cell until log_odds_max (4), footprints -1.5 until
    log_odds_min (-4): after n readings min(3 n, 4) and max(-1.5 n, -4), and the map's entropy
    equals the sum of its cells' entropies at those values."""
    cfg = replace(EXACT, robot_radius_m=0.17, footprint_log_odds=-1.5)
    m = SparseInverseKVisibility(GRID, [ROUTER], cfg)
    contact, here = (10, 32), (10, 30)
    for n in range(1, 7):
        m.update((3.05, 1.05), [-100.0], bumped=True, heading_rad=0.0)
        assert m.log_odds[contact] == pytest.approx(min(3.0 * n, cfg.log_odds_max))
        assert m.log_odds[here] == pytest.approx(max(-1.5 * n, cfg.log_odds_min))
    assert m.entropy_bits == pytest.approx(m.recompute_entropy_bits())
    gain = m.update((3.05, 1.05), [-100.0], bumped=True, heading_rad=0.0)
    assert gain == 0.0  # everything it touches is clamped: no bits left to gain
