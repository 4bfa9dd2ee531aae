"""Tests of the simulated 2-D LiDAR: exact ranges in a square room, range limit, field of view,
noise and dropout, determinism, points, a brute-force cross-check on generated and HouseExpo
plans, and bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from shapely.geometry import Polygon

from sfw_gym.core.errors import ConfigError
from sfw_gym.world import Pose, generate_floorplan, load_floorplan
from sfw_gym.world.floorplan import floorplan_from_polygon
from sfw_gym.world.lidar import Lidar, LidarConfig

ROOM = floorplan_from_polygon(Polygon([(-2, -2), (2, -2), (2, 2), (-2, 2)]), name="4 m room")
EXACT = {"range_noise_std_m": 0.0}


def lidar(plan=ROOM, **overrides) -> Lidar:
    return Lidar(plan, LidarConfig(**{**EXACT, **overrides}))


def scan(sensor: Lidar, pose, seed: int = 0) -> np.ndarray:
    return sensor.scan(pose, np.random.default_rng(seed))


def box_ranges(x: float, y: float, world_angles: np.ndarray, half: float = 2.0) -> np.ndarray:
    """Distance from (x, y) inside the box [-half, half]² to its boundary along each angle."""
    c, s = np.cos(world_angles), np.sin(world_angles)
    with np.errstate(divide="ignore"):
        tx = np.where(c > 0, (half - x) / c, np.where(c < 0, (-half - x) / c, np.inf))
        ty = np.where(s > 0, (half - y) / s, np.where(s < 0, (-half - y) / s, np.inf))
    return np.minimum(tx, ty)


def brute_force(plan, pose, angles: np.ndarray, max_range_m: float) -> np.ndarray:
    """Every beam against every edge (numpy), the nearest hit within range (an edge's ends
    included with 1e-9 of slack, so that a beam through a vertex hits)."""
    x, y, theta = pose
    d = np.stack([np.cos(theta + angles), np.sin(theta + angles)], axis=1)[:, None, :]
    a, e = plan.edges[None, :, :2], (plan.edges[:, 2:] - plan.edges[:, :2])[None]
    w = a - np.array([x, y])
    den = d[..., 0] * e[..., 1] - d[..., 1] * e[..., 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (w[..., 0] * e[..., 1] - w[..., 1] * e[..., 0]) / den
        s = (w[..., 0] * d[..., 1] - w[..., 1] * d[..., 0]) / den
    ok = (den != 0) & (s >= -1e-9) & (s <= 1 + 1e-9) & (t >= 0) & (t <= max_range_m)
    return np.where(ok, t, np.inf).min(axis=1)


def free_poses(plan, n: int, seed: int) -> list[Pose]:
    rng = np.random.default_rng(seed)
    xmin, ymin, xmax, ymax = plan.bounds
    poses: list[Pose] = []
    while len(poses) < n:
        x, y = rng.uniform((xmin, ymin), (xmax, ymax))
        if plan.is_free(np.array([x, y])):
            poses.append(Pose(float(x), float(y), float(rng.uniform(-math.pi, math.pi))))
    return poses


def test_from_the_centre_of_a_4_m_room_each_beam_reaches_the_wall_exactly():
    r = scan(lidar(beams=8), Pose(0.0, 0.0, 0.0))
    # beam 0 points backwards (-π), then every 45°: walls 2 m away, corners 2√2 m
    assert r.tolist() == pytest.approx([2, 2 * math.sqrt(2)] * 4, abs=1e-12)
    sensor = lidar()
    r = scan(sensor, Pose(0.0, 0.0, 0.0))
    assert r[180] == pytest.approx(2.0, abs=1e-12)  # straight ahead
    assert r[225] == pytest.approx(2 * math.sqrt(2), abs=1e-12)  # 45° left: the corner
    assert r == pytest.approx(box_ranges(0.0, 0.0, sensor.angles), abs=1e-12)


def test_ranges_off_centre_and_turned_match_the_geometry():
    sensor = lidar(beams=360)
    pose = Pose(0.5, -0.7, 0.3)
    expected = box_ranges(pose.x, pose.y, pose.theta + sensor.angles)
    assert scan(sensor, pose) == pytest.approx(expected, abs=1e-9)


def test_beyond_the_maximum_range_a_beam_returns_inf():
    assert np.isinf(scan(lidar(max_range_m=1.9), (0.0, 0.0, 0.0))).all()
    r = scan(lidar(beams=8, max_range_m=2.5), (0.0, 0.0, 0.0))
    assert r.tolist() == [2.0, math.inf] * 4  # the walls in range, the corners not


def test_angles_span_the_field_of_view_centred_on_the_heading():
    assert lidar(beams=4).angles == pytest.approx([-math.pi, -math.pi / 2, 0, math.pi / 2])
    half = lidar(beams=5, fov_deg=180.0)
    assert half.angles == pytest.approx(np.linspace(-math.pi / 2, math.pi / 2, 5))
    # heading +y: the middle beam hits the top wall 2 m away, the side ones the side walls
    r = scan(half, (0.0, 0.0, math.pi / 2))
    assert r == pytest.approx([2, 2 * math.sqrt(2), 2, 2 * math.sqrt(2), 2], abs=1e-12)


def test_a_field_of_view_across_the_back_matches_brute_force():
    """The beams of a narrow field of view facing -x straddle ±π, where angles wrap; a heading
    of several turns wraps too."""
    plan = generate_floorplan(1)
    for fov, beams in ((45.0, 7), (90.0, 91), (359.0, 50), (30.0, 1), (360.0, 1)):
        sensor = lidar(plan, fov_deg=fov, beams=beams)
        for pose in free_poses(plan, 10, seed=2):
            for theta in (math.pi - 0.01, -7.0):
                turned = Pose(pose.x, pose.y, theta)
                expected = brute_force(plan, turned, sensor.angles, 8.0)
                assert scan(sensor, turned) == pytest.approx(expected, abs=1e-9)


def test_dropout_drops_about_that_fraction_of_beams():
    r = np.concatenate([scan(lidar(dropout=0.3), (0, 0, 0), seed) for seed in range(20)])
    assert np.isinf(r).mean() == pytest.approx(0.3, abs=0.02)  # 7,200 beams: σ ≈ 0.005


def test_range_noise_has_the_configured_spread():
    sensor = lidar(range_noise_std_m=0.05)
    err = np.concatenate([scan(sensor, (0, 0, 0), seed) for seed in range(20)])
    err -= np.tile(box_ranges(0, 0, sensor.angles), 20)
    assert err.mean() == pytest.approx(0.0, abs=0.004)
    assert err.std() == pytest.approx(0.05, rel=0.05)


def test_noise_never_makes_a_range_negative():
    r = scan(lidar(range_noise_std_m=1.0), (1.99, 0.0, 0.0))  # 1 cm from the wall ahead
    assert (r >= 0).all() and (r == 0).any()


def test_the_same_seed_gives_the_same_scan():
    plan = generate_floorplan(0)
    sensor = Lidar(plan, LidarConfig(range_noise_std_m=0.02, dropout=0.1))
    pose = free_poses(plan, 1, seed=0)[0]
    a, b, c = scan(sensor, pose, 7), scan(sensor, pose, 7), scan(sensor, pose, 8)
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)


def test_points_in_the_robot_frame_and_in_the_world():
    sensor = lidar(beams=4)  # beams at -π, -π/2, 0, +π/2
    pose = Pose(1.0, 0.5, math.pi / 2)  # facing the top wall, 1.5 m away
    r = scan(sensor, pose)
    # beam -π points backwards (-y: 2.5 m), -π/2 right (+x: 1 m), 0 ahead (+y: 1.5 m), +π/2 left
    assert r.tolist() == pytest.approx([2.5, 1.0, 1.5, 3.0])
    robot = sensor.points((0.0, 0.0, 0.0), r)
    assert robot == pytest.approx(np.array([[-2.5, 0], [0, -1.0], [1.5, 0], [0, 3.0]]), abs=1e-12)
    world = sensor.points(pose, r)
    assert world == pytest.approx(np.array([[1, -2], [2, 0.5], [1, 2], [-2, 0.5]]), abs=1e-12)
    r[1] = np.inf  # only the hits
    assert sensor.points((0, 0, 0), r).shape == (3, 2)


@pytest.mark.parametrize("seed", [0, 5, 11])
def test_on_generated_plans_every_hit_is_the_first_wall_along_its_beam(seed):
    plan = generate_floorplan(seed)
    sensor = lidar(plan)
    boundary = plan.free_space.boundary
    for pose in free_poses(plan, 15, seed):
        r = scan(sensor, pose)
        assert r == pytest.approx(brute_force(plan, pose, sensor.angles, 8.0), abs=1e-9)
        hits = sensor.points(pose, r)
        assert shapely.distance(shapely.points(hits), boundary).max() < 1e-6  # on a wall face
        # the beam up to just short of its hit (or to the range) crosses no wall
        reach = np.where(np.isfinite(r), r - 1e-6, 8.0)
        a = pose.theta + sensor.angles
        ends = np.column_stack([pose.x + reach * np.cos(a), pose.y + reach * np.sin(a)])
        lines = shapely.linestrings([[[pose.x, pose.y], end] for end in ends])
        assert not shapely.intersects(lines, boundary).any()


def test_beams_aimed_exactly_at_vertices_stop_there():
    """Both edges at a vertex end exactly on such a beam: round-off must not let it through."""
    plan = generate_floorplan(4)
    sensor = lidar(plan, beams=7, fov_deg=60.0)
    rng = np.random.default_rng(0)
    aimed = 0
    for pose in free_poses(plan, 300, seed=4):
        vx, vy = plan.edges[rng.integers(len(plan.edges)), :2]
        k = int(rng.integers(7))
        theta = math.atan2(vy - pose.y, vx - pose.x) - sensor.angles[k]
        aimed_pose = Pose(pose.x, pose.y, theta)
        expected = brute_force(plan, aimed_pose, sensor.angles, 8.0)
        assert scan(sensor, aimed_pose) == pytest.approx(expected, abs=1e-9)
        aimed += expected[k] == pytest.approx(math.hypot(vx - pose.x, vy - pose.y))
    assert aimed > 50  # the vertex was the first thing along the beam this often


def test_on_houseexpo_plans_ranges_match_brute_force(houseexpo_paths):
    for path in houseexpo_paths[:4]:
        plan = load_floorplan(path)
        sensor = lidar(plan, max_range_m=6.0)
        for pose in free_poses(plan, 5, seed=3):
            expected = brute_force(plan, pose, sensor.angles, 6.0)
            assert scan(sensor, pose) == pytest.approx(expected, abs=1e-9)


@pytest.mark.parametrize(
    ("overrides", "message"),
    [
        ({"beams": 0}, r"lidar\.beams must be an int >= 1, got 0"),
        ({"beams": 2.5}, r"lidar\.beams must be an int"),
        ({"fov_deg": 0}, r"lidar\.fov_deg must be a finite number in \(0, 360\]"),
        ({"fov_deg": 361}, r"lidar\.fov_deg"),
        ({"max_range_m": 0}, r"lidar\.max_range_m must be a finite number > 0"),
        ({"range_noise_std_m": -0.1}, r"lidar\.range_noise_std_m must be a finite number >= 0"),
        ({"dropout": 1.0}, r"lidar\.dropout must be a finite number in \[0, 1\)"),
        ({"beam": 10}, r"unknown key 'beam'; did you mean 'beams'\?"),
    ],
)
def test_bad_settings_are_named(overrides, message):
    with pytest.raises(ConfigError, match=message):
        LidarConfig.from_dict(overrides, "lidar")


def test_bad_poses_and_ranges_are_named():
    sensor = lidar(beams=4)
    rng = np.random.default_rng(0)
    with pytest.raises(ConfigError, match=r"pose must be \(x, y, theta\)"):
        sensor.scan((0.0, 0.0), rng)
    with pytest.raises(ConfigError, match="pose must be finite"):
        sensor.scan((math.nan, 0.0, 0.0), rng)
    with pytest.raises(ConfigError, match=r"ranges must have shape \(4,\), got \(3,\)"):
        sensor.points((0, 0, 0), np.ones(3))


def test_a_scan_draws_from_the_generator_only_what_its_noise_and_dropout_need():
    """No noise and no dropout: the generator is left as it was (the env's other draws keep
    their stream); noise only: exactly one normal per beam."""
    rng = np.random.default_rng(5)
    before = rng.bit_generator.state
    lidar(dropout=0.0).scan((0.0, 0.0, 0.0), rng)
    assert rng.bit_generator.state == before
    noisy, reference = np.random.default_rng(5), np.random.default_rng(5)
    lidar(range_noise_std_m=0.01, dropout=0.0, beams=16).scan((0.0, 0.0, 0.0), noisy)
    reference.normal(0.0, 0.01, 16)
    assert noisy.bit_generator.state == reference.bit_generator.state


def test_a_zero_length_face_is_skipped_and_the_faces_after_it_still_count():
    from sfw_gym.world.lidar import _cast

    edges = np.array([[1.0, 1.0, 1.0, 1.0], [2.0, -1.0, 2.0, 1.0]])  # a point, then a wall
    angles = np.array([0.0])
    out = np.empty(1)
    _cast(edges, 0.0, 0.0, 0.0, np.cos(angles), np.sin(angles), 0.0, 2 * math.pi, 8.0, out)
    assert out.tolist() == [2.0]


def test_a_beam_grazing_a_corner_hits_the_face_just_past_its_start():
    """2 nm above the floor's face, a beam along it meets the far wall 5e-10 of its length
    from the corner: a hit inside the face, not round-off."""
    r = scan(lidar(beams=4), (0.0, -2.0 + 2e-9, 0.0))  # beam 2 points along +x
    assert r[2] == pytest.approx(2.0, abs=1e-12)
