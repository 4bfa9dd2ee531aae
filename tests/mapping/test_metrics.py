"""Map and k-value metrics on tiny hand-made maps."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sfw_gym.core.errors import ConfigError
from sfw_gym.mapping.metrics import (
    coverage,
    entropy_bits,
    evaluate_map,
    free_iou,
    interior_wall_cells,
    interior_wall_recall,
    k_value_accuracy,
    map_iou,
    map_mse,
    wall_precision,
)

W, F, U = 0, 255, 127

# Two rooms (free) split by a 1-cell partition wall (column 3) with outer walls and outside.
TRUTH = np.array(
    [
        [U, U, U, U, U, U, U],
        [W, W, W, W, W, W, W],
        [W, F, F, W, F, F, W],
        [W, F, F, W, F, F, W],
        [W, F, F, W, F, F, W],
        [W, W, W, W, W, W, W],
    ],
    np.uint8,
)


def test_k_value_accuracy_skips_undefined():
    assert k_value_accuracy([0, 1, 2, -1, 1], [0, 1, 1, 0, -1]) == pytest.approx(2 / 3)
    assert math.isnan(k_value_accuracy([-1], [0]))
    with pytest.raises(ConfigError):
        k_value_accuracy([0, 1], [0])


def test_paper_iou_and_mse_over_cells_known_in_both():
    est = np.full(TRUTH.shape, U, np.uint8)
    est[2:5, 1:3] = F  # left room right
    est[2, 3] = F  # wrong: wall cell called free
    est[0, 0] = F  # outside the truth: ignored by the paper's metrics
    # known in both: 6 + 1 cells, 6 agree
    assert map_iou(est, TRUTH) == pytest.approx(6 / 7)
    assert map_mse(est, TRUTH) == pytest.approx(1 / 7)  # one error of (255 / 255)^2
    only_free = np.where(TRUTH == F, F, U).astype(np.uint8)
    assert map_iou(only_free, TRUTH) == 1.0  # why the paper's IoU is not enough


def test_graded_values_are_classified_by_thirds():
    est = np.full(TRUTH.shape, 150, np.uint8)  # unknown third
    assert math.isnan(map_iou(est, TRUTH))
    est[2:5, 1:3] = 200  # free third
    est[2:5, 3] = 60  # wall third
    assert map_iou(est, TRUTH) == 1.0
    assert map_mse(est, TRUTH) == pytest.approx((6 * 55**2 + 3 * 60**2) / 9 / 255**2)


def test_coverage_and_free_iou():
    est = np.full(TRUTH.shape, U, np.uint8)
    est[2:5, 1:3] = F  # 6 of the 12 free cells
    est[2:5, 3] = W  # classified wall: counts for coverage, not for free IoU
    assert coverage(est, TRUTH) == pytest.approx(6 / 12)
    assert free_iou(est, TRUTH) == pytest.approx(6 / 12)
    est[0, 1] = F  # free outside the plan lowers free IoU only
    assert free_iou(est, TRUTH) == pytest.approx(6 / 13)
    assert coverage(est, TRUTH) == pytest.approx(6 / 12)


def test_wall_precision_with_tolerance():
    est = np.full(TRUTH.shape, U, np.uint8)
    est[3, 3] = W  # on the wall
    est[3, 5] = W  # 1 cell from the outer wall (column 6)
    assert wall_precision(est, TRUTH, tolerance_cells=0) == pytest.approx(1 / 2)
    assert wall_precision(est, TRUTH, tolerance_cells=1) == 1.0
    assert math.isnan(wall_precision(np.full(TRUTH.shape, F, np.uint8), TRUTH))
    with pytest.raises(ConfigError, match="tolerance_cells"):
        wall_precision(est, TRUTH, tolerance_cells=-1)


def test_interior_wall_cells_are_the_partition_only():
    interior = interior_wall_cells(TRUTH)
    expected = np.zeros(TRUTH.shape, bool)
    expected[2:5, 3] = True  # free left and right; outer walls face the outside or the edge
    assert np.array_equal(interior, expected)


def test_interior_wall_thicker_than_the_limit_is_not_interior():
    thick = TRUTH.copy()
    thick[2:5, 2:5] = W  # a 3-cell-thick block between 1-cell rooms
    # from its left edge cell (3, 2), free space is 1 step left but 3 steps right
    assert interior_wall_cells(thick, max_thickness_cells=3)[3, 2]
    assert not interior_wall_cells(thick, max_thickness_cells=2)[3, 2]


def test_interior_wall_recall_with_tolerance():
    est = np.full(TRUTH.shape, U, np.uint8)
    est[3, 1] = W  # two cells left of the partition's middle cell
    assert interior_wall_recall(est, TRUTH, tolerance_cells=2) == pytest.approx(1 / 3)
    assert interior_wall_recall(est, TRUTH, tolerance_cells=3) == 1.0  # sqrt(5) <= 3
    assert interior_wall_recall(np.full(TRUTH.shape, U, np.uint8), TRUTH) == 0.0
    no_partition = TRUTH.copy()
    no_partition[2:5, 3] = F
    assert math.isnan(interior_wall_recall(est, no_partition))


def test_evaluate_map_and_entropy():
    m = evaluate_map(TRUTH, TRUTH)
    assert m["paper_iou"] == 1.0 and m["paper_mse"] == 0.0 and m["coverage"] == 1.0
    assert m["free_iou"] == 1.0 and m["wall_precision"] == 1.0
    assert m["interior_wall_recall"] == 1.0
    assert entropy_bits(np.array([0.5, 0.5, 0.0, 1.0])) == pytest.approx(2.0)


def test_shape_mismatch_raises():
    with pytest.raises(ConfigError, match="shape"):
        map_iou(TRUTH[:3], TRUTH)


def test_k_value_accuracy_with_max_k_reads_k_as_k_or_more():
    k_true = np.array([0, 2, 3, 5, 6, -1, 4])
    k_est = np.array([0, 2, 3, 3, 3, 3, -1])
    # strict (Eq. 8): 3 of the 5 comparable samples; the capped estimator is wrong at 5 and 6
    assert k_value_accuracy(k_est, k_true) == pytest.approx(3 / 5)
    # with K = 3, a true 5 or 6 is "3 or more": every comparable sample is right
    assert k_value_accuracy(k_est, k_true, max_k=3) == 1.0
    assert k_value_accuracy(np.array([4]), np.array([6]), max_k=3) == 0.0  # above K: wrong
    for bad in (-1, 1.5, True):
        with pytest.raises(ConfigError, match="max_k"):
            k_value_accuracy(k_est, k_true, max_k=bad)
