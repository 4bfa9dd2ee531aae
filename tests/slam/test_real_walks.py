"""Radio SLAM on walks of real scans (issue 38): a looping walk whose revisits sound alike by
construction, the closure-wrongness rule and the odometry sigmas by hand, and a few WiFine train
walks (skipped where ../shared is absent)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import DATASETS_DIR
from sfw_gym.slam.radio_slam import RadioSlamConfig, heard_readings, odometry_sigmas_m
from sfw_gym.slam.real_walks import (
    real_walk_config,
    slam_on_walk,
    slam_on_walks,
    walk_seed,
    wrong_closures,
)

WIFINE_TRAIN = DATASETS_DIR / "wifine" / "train"


def looping_walk(laps: int = 3, side_m: float = 24.0, step_m: float = 1.6):
    """Positions around a ``side_m`` square, ``laps`` times, a scan every ``step_m``, and their
    readings from 30 access points by a log-distance path loss (no noise): the same place reads
    the same, and the readings drift apart with distance (weak ones below -75 dBm not heard)."""
    along = np.arange(0.0, 4 * side_m * laps, step_m)
    s = np.mod(along, 4 * side_m)
    side, t = np.divmod(s, side_m)
    corners = np.array([[0, 0], [side_m, 0], [side_m, side_m], [0, side_m], [0, 0]], float)
    a, b = corners[side.astype(int)], corners[side.astype(int) + 1]
    positions = a + (b - a) * (t / side_m)[:, None]
    aps = np.random.default_rng(7).uniform(-6.0, side_m + 6.0, (30, 2))
    distance = np.linalg.norm(positions[:, None, :] - aps[None], axis=2)
    rssi = -30.0 - 30.0 * np.log10(np.maximum(distance, 0.5))
    return positions, np.where(rssi >= -90.0, rssi, np.nan)


def test_slam_beats_odometry_on_a_walk_whose_revisits_sound_alike():
    positions, rssi = looping_walk()
    res = slam_on_walk(positions, rssi, translation_std=0.10, heading_std_rad=0.04, seed=3)
    assert res.n_scans == len(positions)
    assert res.length_m == pytest.approx(np.linalg.norm(np.diff(positions, axis=0), axis=1).sum())
    assert res.n_closures > 20
    assert res.ate_slam_m < 0.5 * res.ate_odometry_m
    # the closures join scans a lap apart (at least min_travel_m of walking), judged on truth
    assert (np.diff(res.closures, axis=1) * 1.6 >= 20.0 - 1e-9).all()
    true_m = np.linalg.norm(positions[res.closures[:, 1]] - positions[res.closures[:, 0]], axis=1)
    np.testing.assert_allclose(res.closure_true_m, true_m)
    # no closure is far off (noise-free readings), though many miss by over 3 of their sigmas
    # (the model's bins are narrow here, sigma at its 0.5 m floor)
    assert (np.abs(res.closure_true_m - res.closure_distance_m) < 3.0).all()
    assert res.n_wrong == int(res.wrong.sum()) < res.n_closures / 2


def test_the_closure_wrongness_rule():
    true_m = np.array([2.0, 2.0, 10.0, 2.0, 5.0])
    estimate = np.array([2.5, 6.0, 8.0, 2.0, 3.2])
    sigma = np.array([0.5, 2.0, 0.5, 0.1, 1.0])
    # off by 0.5 (1 sigma): right; by 4 m (2 sigma, but over 3 m): wrong; by 2 m (4 sigma):
    # wrong; exact: right; by 1.8 m (1.8 sigma, under 3 m): right
    np.testing.assert_array_equal(
        wrong_closures(true_m, estimate, sigma), [False, True, True, False, False]
    )
    assert wrong_closures(true_m, estimate, sigma, max_error_m=1.0).tolist() == [
        False, True, True, False, True,
    ]  # fmt: skip


def test_odometry_sigmas_grow_with_each_steps_travel():
    odometry = np.array([[0, 0, 0], [1, 0, 0], [3, 0, 0], [6, 0, 0]], float)  # steps 1, 2, 3 m
    config = RadioSlamConfig(odometry_sigma_m=0.01, odometry_sigma_per_m=0.05)
    sigmas = odometry_sigmas_m(odometry, np.array([0, 2, 3]), config)
    expected = [
        math.sqrt(2 * 0.01**2 + 0.05**2 * (1 + 4)),
        math.sqrt(0.01**2 + 0.05**2 * 9),
    ]
    np.testing.assert_allclose(sigmas, expected)
    # without a per-metre part: the per-step sigma times the root of the steps, as before
    flat = odometry_sigmas_m(odometry, np.array([0, 2, 3]), RadioSlamConfig(odometry_sigma_m=0.02))
    np.testing.assert_allclose(flat, [0.02 * math.sqrt(2), 0.02])


def test_weak_readings_count_as_not_heard_only_when_asked():
    fp = np.array([[-50.0, -80.0, np.nan]])
    np.testing.assert_array_equal(heard_readings(fp, RadioSlamConfig()), fp)
    floored = heard_readings(fp, RadioSlamConfig(min_rssi_dbm=-75.0))
    np.testing.assert_array_equal(np.isnan(floored), [[False, True, True]])


def test_the_real_walk_config_matches_the_odometry_noise():
    config = real_walk_config(0.10, 0.04, threshold=0.5)
    assert config.odometry_sigma_per_m == 0.10 and config.odometry_sigma_rad == 0.04
    assert config.threshold == 0.5 and config.keyframe_every == 1
    a, b = walk_seed(1, "train_4_1").random(), walk_seed(1, "train_4_1").random()
    assert a == b != walk_seed(2, "train_4_1").random()


@pytest.mark.skipif(not WIFINE_TRAIN.is_dir(), reason=f"WiFine not found at {WIFINE_TRAIN}")
def test_radio_slam_beats_odometry_on_real_wifine_walks():
    from sfw_gym.datasets import read_wifine
    from sfw_gym.datasets.readers import concatenate

    names = ("train_4_24", "train_5_1", "train_6_17")
    data = concatenate([read_wifine(WIFINE_TRAIN / f"{n}.csv") for n in names], "three walks")
    runs = list(slam_on_walks(data, translation_std=0.10, heading_std_rad=0.04, seed=0))
    assert sorted(r.label for r in runs) == sorted(names)
    odometry = np.mean([r.ate_odometry_m for r in runs])
    slam = np.mean([r.ate_slam_m for r in runs])
    assert slam < odometry
    assert all(r.n_closures > 0 for r in runs)
    assert sum(r.n_wrong for r in runs) < 0.2 * sum(r.n_closures for r in runs)
