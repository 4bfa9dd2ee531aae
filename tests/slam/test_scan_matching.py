"""ICP scan matching against cases computed by hand: walls sampled every 2 cm on average, scan B
the same points seen from a known pose, so that the true delta is known exactly."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from sfw_gym.core.errors import ConfigError
from sfw_gym.slam.pose_graph import compose_pose, relative_pose
from sfw_gym.slam.scan_matching import IcpConfig, IcpResult, icp

METHODS = ("point_to_line", "point_to_point")


def wall(x0: float, y0: float, x1: float, y1: float) -> np.ndarray:
    """Points from ``(x0, y0)`` to ``(x1, y1)``, one per 2 cm at random places (a LiDAR's are
    unevenly spaced too; on an even grid, point-to-point ICP can lock onto a shift of whole
    samples along a wall, as each B point finds an A point as near as at the truth)."""
    n = round(math.hypot(x1 - x0, y1 - y0) / 0.02)
    t = np.random.default_rng(n).uniform(0.0, 1.0, (n, 1))
    return np.array([x0, y0]) + t * np.array([x1 - x0, y1 - y0])


L_ROOM = [(0, 0), (6, 0), (6, 3), (3, 3), (3, 5), (0, 5), (0, 0)]  # 6 × 5 m less 3 × 2 m


def l_room() -> np.ndarray:
    """The walls of an L-shaped room, 1,100 points."""
    return np.concatenate([wall(*p, *q) for p, q in itertools.pairwise(L_ROOM)])


def seen_from(points: np.ndarray, pose) -> np.ndarray:
    """World ``points`` in the frame of a robot at ``pose``."""
    c, s = math.cos(pose[2]), math.sin(pose[2])
    d = points - np.asarray(pose[:2])
    return np.column_stack([c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1]])


@pytest.mark.parametrize("method", METHODS)
def test_a_known_motion_is_recovered_from_a_guess_off_by_20_cm_and_5_degrees(method):
    a = l_room() - (2.0, 1.5)  # scan A: the room around A's origin
    delta = (0.4, -0.3, 0.25)  # B's frame seen from A's
    b = seen_from(a, delta)  # the same walls in B's frame
    guess = (delta[0] + 0.2, delta[1], delta[2] + math.radians(5))
    cfg = IcpConfig(method=method)
    result = icp(a, b, guess, cfg)
    assert result.converged and result.iterations < cfg.max_iterations
    np.testing.assert_allclose(result.delta[:2], delta[:2], atol=1e-3)
    assert result.delta[2] == pytest.approx(delta[2], abs=1e-4)
    assert result.fitness == pytest.approx(0.0, abs=1e-8)
    assert result.matched == len(b)
    assert result.observability > 0.3  # walls in both directions
    assert result.accepted(len(a), len(b), cfg)


@pytest.mark.parametrize("method", METHODS)
def test_the_delta_composes_pose_a_into_pose_b_as_the_pose_graph_does(method):
    world = l_room()
    pose_a, pose_b = np.array([1.5, 1.0, 2.0]), np.array([2.0, 1.6, 2.3])
    a, b = seen_from(world, pose_a), seen_from(world, pose_b)
    guess = np.array(relative_pose(pose_a, pose_b)) + np.array([-0.1, 0.15, -0.08])
    result = icp(a, b, guess, IcpConfig(method=method))
    assert result.accepted(len(a), len(b))
    got = compose_pose(pose_a, result.delta)
    np.testing.assert_allclose(got[:2], pose_b[:2], atol=1e-3)
    assert got[2] == pytest.approx(pose_b[2], abs=1e-4)


@pytest.mark.parametrize("method", METHODS)
def test_fitness_is_the_mean_squared_distance_of_the_pairs(method):
    """B: A's points pushed 3 cm off their wall, to either side in turn, so that B sits where A
    does and each B point's nearest A point is its own: fitness 0.03² m²."""
    pushed = []
    for p, q in itertools.pairwise(L_ROOM):
        on = wall(*p, *q)
        normal = np.abs(np.subtract(q, p)[::-1]) / math.dist(p, q)  # walls run along x or y
        side = np.where(np.arange(len(on)) % 2 == 0, 1.0, -1.0)
        pushed.append(on + 0.03 * side[:, None] * normal)
    a, b = l_room(), np.concatenate(pushed)
    result = icp(a, b, (0.0, 0.0, 0.0), IcpConfig(method=method))
    assert np.abs(result.delta).max() < 5e-3  # the pushes nearly average out
    assert result.fitness == pytest.approx(0.03**2, rel=0.05)
    assert result.matched == len(b)


def test_a_corridor_passes_the_papers_rule_but_is_rejected_as_unobserved():
    """Two parallel walls: nothing fixes the motion along them, so ICP keeps the guess's 20 cm
    error there while fitness and matched points look perfect; only observability tells."""
    world = np.concatenate([wall(-10, -1, 10, -1), wall(-10, 1, 10, 1)])
    pose_a, pose_b = np.array([0.0, 0.0, 0.0]), np.array([0.5, 0.1, 0.03])
    a, b = seen_from(world, pose_a), seen_from(world, pose_b)
    truth = np.array(relative_pose(pose_a, pose_b))
    paper = IcpConfig(min_observability=0.0)
    result = icp(a, b, truth + np.array([0.2, 0.05, 0.02]), paper)
    assert abs(result.delta[0] - truth[0]) > 0.15  # slid along the corridor
    assert result.delta[1:] == pytest.approx(truth[1:], abs=1e-3)  # across it: recovered
    assert result.fitness < 1e-3 and result.matched == len(b)
    assert result.observability < 1e-6
    assert result.accepted(len(a), len(b), paper)
    assert not result.accepted(len(a), len(b))  # the default config's guard
    for method in METHODS:
        assert not icp(a, b, truth, IcpConfig(method=method)).accepted(len(a), len(b))


@pytest.mark.parametrize("method", METHODS)
def test_an_unrelated_scan_is_not_accepted(method):
    """Clutter spread over 10 × 10 m: a fifth of it lies within 0.5 m of a wall, so the matched
    pairs' fitness (about 0.5²/3 m²) may pass, but the matched fraction fails."""
    a = l_room() - (2.0, 1.5)
    b = np.random.default_rng(0).uniform(-5.0, 5.0, (500, 2))
    result = icp(a, b, (0.0, 0.0, 0.0), IcpConfig(method=method))
    assert result.matched < 0.5 * 0.5 * (len(a) + len(b))
    assert not result.accepted(len(a), len(b))


def test_the_acceptance_rule_is_the_papers():
    """Fitness below 0.1 m² and matched above half of the two scans' mean count (100 and 200
    points: more than 75), both strict."""
    cfg = IcpConfig()

    def ok(fitness: float, matched: int, observability: float = 0.3) -> bool:
        return IcpResult(np.zeros(3), fitness, matched, 5, True, observability).accepted(
            100, 200, cfg
        )

    assert ok(0.05, 76)
    assert not ok(0.05, 75)
    assert not ok(0.1, 200)
    assert not ok(0.05, 76, observability=0.01)
    assert not ok(math.inf, 200)


def test_too_few_points_fail_without_an_exception():
    a = l_room()
    for b in (np.zeros((0, 2)), [], a[:2]):
        result = icp(a, b, (0.0, 0.0, 0.0))
        assert not result.converged and result.fitness == math.inf
        assert result.delta.tolist() == [0.0, 0.0, 0.0]
        assert result.matched == len(b)  # counted: each point lies on a wall of A
        assert not result.accepted(len(a), len(b))
    two, three = np.array([[0.0, 0.0], [1.0, 0.0]]), np.array([[0.0, 0.1], [1.0, 0.1], [5.0, 5.0]])
    assert icp(two, three).matched == 2  # the third point is 5 m away
    far = icp(a, a + 100.0, (0.3, 0.2, 0.1))  # no pair within reach
    assert far.matched == 0 and not far.converged and far.delta.tolist() == [0.3, 0.2, 0.1]


def test_bad_input_is_a_one_line_config_error():
    a = l_room()
    nan_b = a.copy()
    nan_b[7, 1] = np.nan
    with pytest.raises(ConfigError, match="points_b has NaN or infinite"):
        icp(a, nan_b)
    with pytest.raises(ConfigError, match="points_a has NaN or infinite"):
        icp(np.r_[a, [[np.inf, 0.0]]], a)
    with pytest.raises(ConfigError, match=r"points_a must be an \(N, 2\) array"):
        icp(a[:, :1], a)
    with pytest.raises(ConfigError, match="initial must be 3 finite"):
        icp(a, a, (0.0, math.nan, 0.0))
    with pytest.raises(ConfigError, match=r"icp\.method"):
        IcpConfig(method="point_to_plane")
    with pytest.raises(ConfigError, match="did you mean 'max_iterations'"):
        IcpConfig.from_dict({"max_iteration": 5})
