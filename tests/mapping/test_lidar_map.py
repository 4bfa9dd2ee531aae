"""Tests of the LiDAR occupancy grid: single beams computed by hand, one update per cell per
scan, clamping, the uint8 encoding, and maps of real scans scored by the map metrics."""

from __future__ import annotations

import math

import numpy as np
import pytest
from shapely.geometry import Polygon

from sfw_gym.core.constants import U8_FREE, U8_UNKNOWN, U8_WALL
from sfw_gym.core.errors import ConfigError
from sfw_gym.mapping import GridSpec, metrics
from sfw_gym.mapping.lidar_map import LidarOccupancyMap
from sfw_gym.world import Pose, generate_floorplan
from sfw_gym.world.floorplan import floorplan_from_polygon
from sfw_gym.world.lidar import Lidar, LidarConfig

GRID = GridSpec((0.0, 0.0), 1.0, (3, 6))  # 1 m cells, 6 across (x), 3 up (y)
F, H = -0.4, 0.85  # the default l_free (a beam passed), l_occ (a beam ended: a hit)


def one_scan(angles, ranges, pose=(0.5, 1.5, 0.0), grid=GRID, max_range_m=10.0, times=1, **kw):
    m = LidarOccupancyMap(grid, **kw)
    for _ in range(times):
        m.integrate(pose, np.array(angles, float), np.array(ranges, float), max_range_m)
    return m


def test_one_beam_frees_the_cells_it_crosses_and_marks_the_cell_it_ends_in():
    lo = one_scan([0.0], [3.0]).log_odds  # from the centre of cell (1, 0) to x = 3.5
    assert lo[1].tolist() == [F, F, F, H, 0, 0]
    assert not lo[[0, 2]].any()


def test_a_hit_on_a_cell_border_marks_the_cell_beyond_it():
    lo = one_scan([0.0], [3.5]).log_odds  # ends at x = 4.0, the face of cell (1, 4)
    assert lo[1].tolist() == [F, F, F, F, H, 0]


def test_a_beam_that_returned_nothing_frees_up_to_the_maximum_range():
    lo = one_scan([0.0], [math.inf], max_range_m=2.0).log_odds  # up to x = 2.5
    assert lo[1].tolist() == [F, F, F, 0, 0, 0]


def test_a_beam_leaving_the_grid_frees_what_lies_inside():
    lo = one_scan([0.0], [10.0]).log_odds
    assert lo[1].tolist() == [F] * 6 and not lo[[0, 2]].any()


def test_a_hit_just_past_the_grid_s_far_edge_marks_nothing():
    lo = one_scan([0.0], [5.6]).log_odds  # ends at x = 6.1, in the column after the last
    assert lo[1].tolist() == [F] * 6 and not lo[[0, 2]].any()


def test_a_diagonal_beam_through_cell_corners():
    lo = one_scan([math.pi / 4], [2 * math.sqrt(2)], pose=(0.5, 0.5, 0.0)).log_odds
    assert np.argwhere(lo == F).tolist() == [[0, 0], [1, 1]]
    assert np.argwhere(lo == H).tolist() == [[2, 2]]


def test_rows_follow_y_and_columns_x_from_the_grid_origin():
    grid = GridSpec((10.0, 20.0), 0.5, (4, 3))
    lo = one_scan([0.0], [1.0], pose=(10.25, 20.25, math.pi / 2), grid=grid).log_odds
    assert lo[:, 0].tolist() == [F, F, H, 0]  # up the first column: y = 20.25 -> 21.25
    assert not lo[:, 1:].any()


def test_each_cell_is_updated_once_per_scan_and_a_hit_wins():
    # two beams along row 1: the first ends in cell 3, the second passes it and ends in cell 5
    lo = one_scan([0.0, 0.0], [3.0, 5.0]).log_odds
    assert lo[1].tolist() == [F, F, F, H, F, H]
    # scans add up
    lo = one_scan([0.0, 0.0], [3.0, 5.0], times=2).log_odds
    assert lo[1].tolist() == pytest.approx([2 * F, 2 * F, 2 * F, 2 * H, 2 * F, 2 * H])


def test_log_odds_are_clamped():
    lo = one_scan([0.0], [3.0], times=20).log_odds  # 20 × -0.4 = -8, 20 × 0.85 = 17
    assert lo[1].tolist() == [-5, -5, -5, 5, 0, 0]
    lo = one_scan([0.0], [3.0], times=20, clamp=1.0, l_free=-0.3, l_occ=0.5).log_odds
    assert lo[1].tolist() == [-1, -1, -1, 1, 0, 0]


def test_probability_and_the_uint8_encoding():
    m = one_scan([0.0], [3.0])
    p = m.probability()[1]
    assert p.tolist() == pytest.approx(
        [1 / (1 + math.e**0.4)] * 3 + [1 / (1 + math.e**-0.85)] + [0.5] * 2
    )
    # one free update (P 0.40) is not yet free; one hit (P 0.7006) is a wall
    assert m.occupancy_u8()[1].tolist() == [U8_UNKNOWN] * 3 + [U8_WALL] + [U8_UNKNOWN] * 2
    m = one_scan([0.0], [3.0], times=3)  # log-odds -1.2: P 0.23
    assert m.occupancy_u8()[1].tolist() == [U8_FREE] * 3 + [U8_WALL] + [U8_UNKNOWN] * 2
    assert m.occupancy_u8().dtype == np.uint8
    assert m.occupancy_u8(threshold_free=0.2)[1, 0] == U8_UNKNOWN


def test_a_room_mapped_from_three_scans_has_its_walls_on_the_boundary():
    """A 4 x 2 m room whose wall faces lie on cell borders: exact scans give the true map;
    noisy ones put hits either side of a face, so walls are found within a cell."""
    plan = floorplan_from_polygon(Polygon([(0, 0), (4, 0), (4, 2), (0, 2)]), name="4 x 2 m")
    truth, origin = plan.rasterize(0.1)
    grid = GridSpec(origin, 0.1, truth.shape)
    free = truth == U8_FREE
    beside = np.zeros_like(free)  # the inner face of the wall: wall cells beside a free cell
    beside[1:] |= free[:-1]
    beside[:-1] |= free[1:]
    beside[:, 1:] |= free[:, :-1]
    beside[:, :-1] |= free[:, 1:]
    face = (truth == U8_WALL) & beside
    for noise, tolerance in ((0.0, 0), (0.01, 1)):
        lidar = Lidar(plan, LidarConfig(beams=720, range_noise_std_m=noise))
        rng = np.random.default_rng(0)
        m = LidarOccupancyMap(grid)
        for pose in (Pose(1.0, 1.0, 0.0), Pose(3.0, 1.0, 2.0), Pose(2.0, 0.5, -1.0)):
            m.integrate(pose, lidar.angles, lidar.scan(pose, rng), lidar.config.max_range_m)
        est = m.occupancy_u8()
        assert metrics.wall_precision(est, truth, tolerance_cells=tolerance) == 1.0
        assert metrics.free_iou(est, truth) > (0.99 if noise == 0 else 0.8)
        assert np.mean(est[face] == U8_WALL) > 0.95


def test_a_generated_plan_mapped_along_poses_scores_like_the_env_map():
    plan = generate_floorplan(3)
    truth, origin = plan.rasterize(0.1)
    lidar = Lidar(plan)
    m = LidarOccupancyMap(GridSpec(origin, 0.1, truth.shape))
    rng = np.random.default_rng(3)
    xmin, ymin, xmax, ymax = plan.bounds
    scans = 0
    while scans < 150:
        x, y = rng.uniform((xmin, ymin), (xmax, ymax))
        if plan.is_free(np.array([x, y])):
            pose = (x, y, rng.uniform(-math.pi, math.pi))
            m.integrate(pose, lidar.angles, lidar.scan(pose, rng), lidar.config.max_range_m)
            scans += 1
    scores = metrics.evaluate_map(m.occupancy_u8(), truth)
    assert scores["free_iou"] > 0.9
    assert scores["wall_precision"] > 0.95
    assert scores["interior_wall_recall"] > 0.9


def test_bad_input_is_named():
    with pytest.raises(ConfigError, match=r"l_free must be a finite number < 0, got 0\.1"):
        LidarOccupancyMap(GRID, l_free=0.1)
    with pytest.raises(ConfigError, match="l_occ must be a finite number > 0"):
        LidarOccupancyMap(GRID, l_occ=math.nan)
    with pytest.raises(ConfigError, match="clamp must be a finite number > 0"):
        LidarOccupancyMap(GRID, clamp=0.0)
    m = LidarOccupancyMap(GRID)
    with pytest.raises(ConfigError, match=r"pose must be a finite \(x, y, theta\)"):
        m.integrate((0.5, 1.5), np.zeros(1), np.ones(1), 8.0)
    with pytest.raises(ConfigError, match="angles and ranges must be of one"):
        m.integrate((0.5, 1.5, 0.0), np.zeros(2), np.ones(3), 8.0)
    with pytest.raises(ConfigError, match="ranges must be >= 0 or inf"):
        m.integrate((0.5, 1.5, 0.0), np.zeros(1), np.array([math.nan]), 8.0)
    with pytest.raises(ConfigError, match="max_range_m must be a finite number > 0"):
        m.integrate((0.5, 1.5, 0.0), np.zeros(1), np.ones(1), math.inf)
    with pytest.raises(ConfigError, match="thresholds need"):
        m.occupancy_u8(threshold_free=0.6)
    with pytest.raises(ConfigError, match=r"thresholds need 0 < threshold_free"):
        m.occupancy_u8(threshold_free=0.0)
    assert not m.log_odds.any()  # nothing half-applied
