"""Radio SLAM on walks of real scans (issue 38): a looping walk whose revisits sound alike by
construction, the closure-wrongness rule and the odometry sigmas by hand, and a few WiFine train
walks (skipped where ../shared is absent)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sfw_gym.core.angles import wrap_angle
from sfw_gym.core.errors import ConfigError
from sfw_gym.datasets.odometry import synthetic_odometry, walk_poses
from sfw_gym.slam.metrics import absolute_trajectory_error
from sfw_gym.slam.pose_graph import PoseGraph, relative_pose
from sfw_gym.slam.radio_slam import (
    RadioSlamConfig,
    heard_readings,
    lateral_offsets,
    odometry_sigmas_m,
    radio_slam,
    snapped_turns,
    travel_directions,
)
from sfw_gym.slam.real_walks import (
    real_walk_config,
    slam_on_walk,
    slam_on_walks,
    walk_seed,
    wrong_closures,
)
from tests.conftest import DATASETS_DIR

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


def test_corridor_closures_beat_range_only_closures_on_the_looping_walk():
    positions, rssi = looping_walk()
    runs = {}
    for name, sigma in (("range only", 0.0), ("corridor", 1.5)):
        config = real_walk_config(0.10, 0.04, corridor_sigma_m=sigma)
        runs[name] = [
            slam_on_walk(positions, rssi, translation_std=0.10, heading_std_rad=0.04, seed=s,
                         config=config)
            for s in (3, 4)
        ]  # fmt: skip
    plain, corridor = runs["range only"], runs["corridor"]
    assert all(r.corridor is None and r.n_corridor == 0 for r in plain)
    for r in corridor:
        # the square's sides are walked the same way each lap: most closures are corridor ones,
        # and each one's scans lie on one side's line (true lateral offset well under 3 m)
        assert r.n_corridor > 0.8 * r.n_closures and r.n_wrong_corridor == 0
        assert (r.corridor_true_m[r.corridor] < 1.0).mean() > 0.9
    ate = {name: np.mean([r.ate_slam_m for r in rs]) for name, rs in runs.items()}
    assert ate["corridor"] < 0.75 * ate["range only"]


def test_heading_closures_snap_the_odometry_turn():
    turns = np.array([0.1, 3.0, -1.5, 0.8, 2.2, -3.1])
    # off by default: no heading closure
    assert not snapped_turns(turns, RadioSlamConfig())[1].any()
    quarter, ok = snapped_turns(turns, RadioSlamConfig(heading_snap_deg=90.0))
    np.testing.assert_allclose(
        np.cos(quarter - np.array([0, np.pi, -np.pi / 2, np.pi / 2, np.pi / 2, np.pi])), 1.0
    )
    assert ok.all()  # every turn lies within 45 deg of a multiple of 90
    half, ok = snapped_turns(
        turns, RadioSlamConfig(heading_snap_deg=180.0, heading_max_off_rad=0.5)
    )
    np.testing.assert_allclose(np.cos(half[ok] - np.array([0.0, np.pi, np.pi])), 1.0)
    assert ok.tolist() == [True, True, False, False, False, True]  # 1.5, 0.8, 2.2: too far off


def test_travel_directions_and_lateral_offsets():
    odo = np.array([[0, 0, 0.3], [1, 0, -0.2], [2, 0, 0.1], [2, 1, 0.0], [2, 2, 2.0]], float)
    np.testing.assert_allclose(travel_directions(odo, 0), odo[:, 2])
    # from one pose before to one after: along x, then the diagonal, then up y
    np.testing.assert_allclose(
        travel_directions(odo, 1), [0.0, 0.0, np.pi / 4, np.pi / 2, np.pi / 2]
    )
    a = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, np.pi / 2]])
    b = np.array([[5.0, -1.5, 1.0], [2.0, 7.0, 0.0]])
    np.testing.assert_allclose(lateral_offsets(a, b), [1.5, 2.0])


def test_heading_closures_correct_the_heading_drift_of_a_loop():
    """Three laps of a square with heading drift only (well under 45 deg a lap): rotation edges
    between scans a lap apart, their turns snapped from the odometry's own, pull the headings
    and the positions back."""
    positions, _ = looping_walk()
    n, per = len(positions), round(4 * 24.0 / 1.6)
    _, odo = synthetic_odometry(positions, translation_std=0.0, heading_std_rad=0.02, rng=1)
    i = np.arange(0, n - per, 3)
    j = i + per
    turn, ok = snapped_turns(odo[j, 2] - odo[i, 2], RadioSlamConfig(heading_snap_deg=90.0))
    truth = walk_poses(positions)[:, 2]
    assert ok.all()
    np.testing.assert_allclose(np.cos(turn - (truth[j] - truth[i])), 1.0, atol=1e-9)

    def solve(rotations: bool) -> np.ndarray:
        graph = PoseGraph(n, robust="cauchy", robust_scale=0.5)
        for k in range(n - 1):
            graph.add_odometry(k, k + 1, relative_pose(odo[k], odo[k + 1]), 0.01, 0.02)
        if rotations:
            for a, b, t in zip(i.tolist(), j.tolist(), turn.tolist(), strict=True):
                graph.add_rotation(a, b, t, 0.05, robust_scale=3.0)
        return graph.optimize(odo)

    plain, fixed = solve(False), solve(True)
    heading_error = {
        name: np.sqrt(np.mean(wrap_angle(x[:, 2] - truth) ** 2)) for name, x in
        (("odometry", odo), ("plain", plain), ("fixed", fixed))
    }  # fmt: skip
    assert heading_error["plain"] == pytest.approx(heading_error["odometry"], rel=1e-3)
    assert heading_error["fixed"] < 0.3 * heading_error["odometry"]
    ate_odometry = absolute_trajectory_error(odo, positions)
    assert absolute_trajectory_error(fixed, positions) < 0.5 * ate_odometry


def test_rotation_and_lateral_edges_by_finite_differences():
    graph = PoseGraph(4, robust="cauchy", robust_scale=1.0)
    graph.add_range(0, 1, 2.0, 0.5)
    graph.add_rotation(1, 2, 0.5, 0.2, robust_scale=2.0)
    graph.add_rotation(0, 3, -1.0, 0.1)
    graph.add_lateral(0, 2, 0.3, 0.7, robust_scale=3.0)
    x = np.random.default_rng(0).normal(size=(4, 3))
    edges = (
        np.zeros((0, 7)),
        np.array(graph._rng),
        np.array(graph._rot),
        np.array(graph._lat),
    )
    _, _, errors = graph._linearize(x, x[0], None, edges)
    assert len(errors) == 4  # one range, two rotation, one lateral
    weights = graph._robust_weights(errors)
    scales = np.array([1.0, 2.0, 1.0, 3.0])  # the graph's scale where an edge names none
    np.testing.assert_allclose(weights, 1.0 / (1.0 + (errors / scales) ** 2))
    r, jac, _ = graph._linearize(x, x[0], weights, edges)
    numeric = np.zeros(jac.shape)
    for c in range(12):
        step = np.zeros(12)
        step[c] = 1e-6
        numeric[:, c] = (
            graph._linearize(x + step.reshape(4, 3), x[0], weights, edges)[0] - r
        ) / 1e-6
    np.testing.assert_allclose(numeric[3:], jac.toarray()[3:], atol=1e-4)  # past the gauge prior
    # the lateral edge: pose 2 off pose 0's line of travel, less the 0.3 m asked for, in sigmas
    c, s = np.cos(x[0, 2]), np.sin(x[0, 2])
    d = x[2, :2] - x[0, :2]
    assert errors[3] == pytest.approx((-s * d[0] + c * d[1] - 0.3) / 0.7)
    with pytest.raises(ConfigError):
        graph.add_lateral(0, 1, 0.0, 0.0)
    with pytest.raises(ConfigError):
        graph.add_rotation(0, 1, 0.0, -1.0)


def test_new_closures_are_off_by_default():
    positions, rssi = looping_walk(laps=2)
    _, odo = synthetic_odometry(positions, translation_std=0.05, heading_std_rad=0.02, rng=0)
    config = RadioSlamConfig(keyframe_every=1, min_rssi_dbm=-75.0, threshold=0.4)
    assert config.corridor_sigma_m == 0.0 and config.heading_snap_deg == 0.0
    result = radio_slam(odo, rssi, config)
    assert result.closure_turn_rad is None and result.closure_corridor is None
    on = radio_slam(odo, rssi, RadioSlamConfig(**(config.__dict__ | {"corridor_sigma_m": 1.5})))
    assert on.closure_corridor is not None and on.closure_corridor.any()


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
    assert config.corridor_sigma_m > 0 and config.heading_snap_deg == 0  # corridor closures on
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
