"""The mapper's update run dry (issue 51): equal to the real update to the bit, by hand and on
random walks; every path starts from the snapshot; where an update's bits come from."""

from __future__ import annotations

import copy
import math
from dataclasses import replace

import gymnasium as gym
import numpy as np
import pytest

import sfw_gym  # noqa: F401
from sfw_gym.core.errors import ConfigError
from sfw_gym.mapping import SparseInverseKVisibility, ray_cells
from sfw_gym.mapping.dry_run import DryRun, feature_for_k
from sfw_gym.mapping.k_estimation import k_from_thresholds
from sfw_gym.mapping.sparse import GAIN_SOURCES
from tests.mapping.test_sparse_mapper import EXACT, GRID, ROUTER, rssi_k


def h(lo: float) -> float:
    """Binary entropy (bits) of a cell at log-odds ``lo``."""
    q = 1.0 / (1.0 + math.exp(-lo))
    return -(q * math.log2(q) + (1 - q) * math.log2(1 - q))


def dry_and_real(mapper, p, k):
    """The dry run's bits for a reading at ``p`` with ``k``, and a twin's real update's."""
    dry = DryRun.of_mapper(mapper).path_gains(np.array([p]), [0], [k])[0]
    twin = copy.deepcopy(mapper)
    real = twin.update(p, rssi_k(p, k))
    assert twin.last_k.tolist() == [k]
    return dry, real


@pytest.mark.parametrize("radius", [0.0, 0.12])
@pytest.mark.parametrize(
    "history, p, k",
    [
        ([], (4.05, 1.05), 0),  # the first reading: footprint and a free ray
        ([((2.05, 1.05), 0)], (5.05, 1.05), 1),  # a wall between two readings on one ray
        ([((2.05, 1.05), 0)], (5.05, 1.05), 3),  # three walls: three peaks
        ([((5.05, 1.05), 2)], (2.05, 1.05), 0),  # k falls: the piece is skipped
        ([((2.05, 1.45), 1), ((4.05, 1.45), 1)], (5.55, 1.05), 1),  # cut past the robot
    ],
)
def test_one_dry_step_equals_the_real_update_to_the_bit(radius, history, p, k):
    m = SparseInverseKVisibility(GRID, [ROUTER], replace(EXACT, robot_radius_m=radius))
    for q, kq in history:
        m.update(q, rssi_k(q, kq))
    dry, real = dry_and_real(m, p, k)
    assert real > 0
    assert dry == pytest.approx(real, abs=1e-12)


def test_a_dry_path_equals_the_real_updates_along_it():
    m = SparseInverseKVisibility(GRID, [ROUTER], EXACT)
    path = [(1.05 + 0.1 * i, 1.05 + 0.02 * i) for i in range(30)]
    ks = [0 if x < 2.6 else 1 for x, _ in path]  # a wall at 2.6 m
    dry = DryRun.of_mapper(m).path_gains(np.array(path), np.zeros(30, int), np.array(ks))
    real = [m.update(q, rssi_k(q, kq)) for q, kq in zip(path, ks, strict=True)]
    np.testing.assert_allclose(dry, real, atol=1e-12)


def test_the_dry_run_on_random_walks_equals_the_env_mapper():
    """From the env's mapper mid-episode (thresholds fitted, a long trajectory raster)."""
    env = gym.make("SfW-Explore-v0")
    env.reset(seed=5)
    u = env.unwrapped
    rng = np.random.default_rng(0)
    checked = 0
    for t in range(300):
        if t % 15 == 14:
            m = u.mapper
            twin = copy.deepcopy(m)
            pose = u.pose_estimate
            xy = np.array([pose[:2]]) + rng.normal(0.0, 0.05, (1, 2))
            rssi = u.rssi_history.view[-1].astype(np.float64)
            real = twin.update(xy[0], rssi)
            router = int(twin.last_routers[0]) if len(twin.last_routers) else -1
            k = int(twin.last_k[router]) if router >= 0 else 0
            dry = DryRun.of_mapper(m).path_gains(xy, [router], [k])[0]
            assert dry == pytest.approx(real, abs=1e-9)
            checked += real > 0
        env.step(np.array([abs(rng.uniform(-1, 1)), rng.uniform(-1, 1)]))
    assert checked >= 10


def test_every_path_starts_from_the_snapshot_and_the_mapper_is_untouched():
    m = SparseInverseKVisibility(GRID, [ROUTER], EXACT)
    m.update((2.05, 1.05), rssi_k((2.05, 1.05), 0))
    before = m.log_odds.copy()
    dry = DryRun.of_mapper(m)
    path = np.array([(3.05 + 0.1 * i, 1.25) for i in range(10)])
    alone = dry.path_gains(path, np.zeros(10, int), np.ones(10, int))
    pair = np.concatenate([path, path])
    both = dry.path_gains(pair, np.zeros(20, int), np.ones(20, int), [0, 10])
    np.testing.assert_array_equal(both[:10], alone)
    np.testing.assert_array_equal(both[10:], alone)
    twice = dry.path_gains(pair, np.zeros(20, int), np.ones(20, int))
    np.testing.assert_array_equal(twice[:10], alone)  # one path: its second half sees the first
    assert not np.array_equal(twice[10:], alone)
    np.testing.assert_array_equal(m.log_odds, before)


def test_a_snapshot_is_its_own_copy_and_bad_input_is_named():
    m = SparseInverseKVisibility(GRID, [ROUTER], EXACT)
    dry = DryRun.of_mapper(m)
    p = np.array([(3.05, 1.05)])
    first = dry.path_gains(p, [0], [0])
    m.update((3.05, 1.05), rssi_k((3.05, 1.05), 0))  # the mapper moves on
    np.testing.assert_array_equal(dry.path_gains(p, [0], [0]), first)
    assert DryRun.of_mapper(m).path_gains(p, [0], [0])[0] != first[0]
    with pytest.raises(ConfigError, match="inside the grid"):
        dry.path_gains(np.array([(99.0, 1.0)]), [0], [0])
    with pytest.raises(ConfigError, match="router indices"):
        dry.path_gains(np.array([(1.0, 1.0)]), [3], [0])
    with pytest.raises(ConfigError, match="starts must ascend"):
        dry.path_gains(np.array([(1.0, 1.0)] * 3), [0], [0], [0, 2, 1])


def test_the_robot_view_snapshots_the_same_mapper():
    env = gym.make("SfW-Explore-v0")
    env.reset(seed=1)
    for _ in range(60):
        env.step(np.array([0.8, 0.3]))
    u = env.unwrapped
    xy = np.array(u.pose_estimate[:2]) + np.array([[0.1 * i, 0.05 * i] for i in range(8)])
    args = (np.zeros(8, int), np.arange(8) % 2)
    from_view = DryRun.of_view(u.robot_view()).path_gains(xy, *args)
    np.testing.assert_array_equal(from_view, DryRun.of_mapper(u.mapper).path_gains(xy, *args))
    assert from_view.sum() > 0


@pytest.mark.parametrize("n_thr", [0, 1, 3])
def test_the_feature_written_for_k_reads_back_as_k(n_thr):
    thresholds = np.array([-30.0, -50.0, -40.0])
    for k in range(5):
        f = feature_for_k(k, thresholds, n_thr)
        assert k_from_thresholds(f, thresholds, n_thr) == min(k, n_thr)


def test_the_first_reading_in_sight_splits_into_footprint_and_line_of_sight_by_hand():
    m = SparseInverseKVisibility(GRID, [ROUTER], replace(EXACT, robot_radius_m=0.12))
    p = (4.05, 1.05)
    gain = m.update(p, rssi_k(p, 0))
    src = m.last_gain_by_source
    assert list(src) == list(GAIN_SOURCES)
    n_ray = len(ray_cells(GRID, ROUTER, p))
    # five footprint cells at -1.0; the ray's cells short of the robot's at -0.4, one of them
    # (10, 39) already in the footprint (-1.0 -> -1.4)
    assert src["footprint"] == pytest.approx(5 * (1 - h(-1.0)))
    los = (n_ray - 2) * (1 - h(-0.4)) + h(-1.0) - h(-1.4)
    assert src["line_of_sight"] == pytest.approx(los)
    assert src["out_of_sight"] == src["past_robot"] == src["walls"] == 0.0
    assert sum(src.values()) == pytest.approx(gain)


def test_sources_tell_walls_out_of_sight_and_past_the_robot():
    m = SparseInverseKVisibility(GRID, [ROUTER], EXACT)
    a, b = (2.05, 1.05), (5.05, 1.05)
    m.update(a, rssi_k(a, 0))
    m.update(b, rssi_k(b, 1))
    assert m.last_gain_by_source["walls"] > 0
    assert m.last_gain_by_source["line_of_sight"] > 0  # router .. a again: k = 0 at both ends
    c = (4.05, 1.05)  # between a and b, with b's k: the stretch c .. b is freed past it
    m.update(c, rssi_k(c, 1))
    assert m.last_gain_by_source["past_robot"] > 0
    d = (5.85, 1.05)  # beyond b with b's k: b .. d is out of the router's sight, and free
    gain = m.update(d, rssi_k(d, 1))
    src = m.last_gain_by_source
    assert src["out_of_sight"] > 0
    assert sum(src.values()) == pytest.approx(gain)


def test_a_snapshot_keeps_its_belief_however_often_the_mapper_moves_on():
    """The snapshot copies the log-odds: runs after the mapper's updates still start from the
    belief it was taken at (its scratch cells are restored from its own copy, not the mapper)."""
    m = SparseInverseKVisibility(GRID, [ROUTER], EXACT)
    m.update((2.05, 1.05), rssi_k((2.05, 1.05), 0))
    dry = DryRun.of_mapper(m)
    p = np.array([(3.05, 1.05), (3.15, 1.05)])
    first = dry.path_gains(p, [0, 0], [0, 0])
    for x in (3.05, 3.15, 3.25):
        m.update((x, 1.05), rssi_k((x, 1.05), 0))
        np.testing.assert_array_equal(dry.path_gains(p, [0, 0], [0, 0]), first)
