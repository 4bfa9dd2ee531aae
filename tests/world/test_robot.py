"""Tests of the pymunk robot: kinematics, limits, walls, bumps, odometry, pickling, bad input."""

from __future__ import annotations

import copy
import math
import pickle

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import sfw_gym.world.robot as robot_module
from sfw_gym.core.errors import ConfigError
from sfw_gym.world.robot import Pose, Robot, RobotConfig, StepResult

CFG = RobotConfig()
R = CFG.radius_m
V_MAX = CFG.max_linear_speed_m_s
W_MAX = CFG.max_angular_speed_rad_s
T = CFG.control_period_s
TOL_M = 1e-3  # how far inside its radius the robot's centre may come to a wall line

NO_WALLS = np.zeros((0, 4))
BOX = np.array([[0, 0, 4, 0], [4, 0, 4, 4], [4, 4, 0, 4], [0, 4, 0, 0]], dtype=float)


def thin_wall_room(x0: float = 2.0, thickness: float = 0.1) -> np.ndarray:
    """A 4 x 4 m box split by a thin rectangular wall (outline of 4 segments), wall to wall."""
    x1 = x0 + thickness
    rect = [[x0, 0, x1, 0], [x1, 0, x1, 4], [x1, 4, x0, 4], [x0, 4, x0, 0]]
    return np.vstack([BOX, np.array(rect, dtype=float)])


def wall_distance(xy: tuple[float, float] | Pose, walls: np.ndarray) -> float:
    """Distance from a point to the nearest wall line."""
    p = np.array(xy[:2], dtype=float)
    a, d = walls[:, :2], walls[:, 2:] - walls[:, :2]
    t = np.clip(np.einsum("ij,ij->i", p - a, d) / np.einsum("ij,ij->i", d, d), 0.0, 1.0)
    return float(np.min(np.hypot(*(p - (a + t[:, None] * d)).T)))


def make(walls=NO_WALLS, pose=(0.0, 0.0, 0.0), seed=0, **cfg) -> Robot:
    return Robot(walls, RobotConfig(**cfg), pose, np.random.default_rng(seed))


# ---------------------------------------------------------------- configuration


def test_default_config_is_sane():
    assert CFG.radius_m == 0.17 and CFG.control_period_s == 0.2
    # A substep moves the robot a small fraction of a 0.1 m wall, and no more than the wall skin.
    assert CFG.max_substep_travel_m <= 0.1 / 4
    assert CFG.max_substep_travel_m <= CFG.wall_radius_m
    assert CFG.odometry_translation_std == 0.0 and CFG.odometry_heading_std_rad == 0.0


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("radius_m", 0.0),
        ("radius_m", -0.1),
        ("radius_m", float("nan")),
        ("max_linear_speed_m_s", 0.0),
        ("max_linear_speed_m_s", float("inf")),
        ("max_angular_speed_rad_s", -1.0),
        ("control_period_s", 0.0),
        ("control_period_s", "0.2"),
        ("physics_substeps", 0),
        ("physics_substeps", 2.5),
        ("physics_substeps", True),
        ("physics_substeps", 1),  # 0.1 m per substep at full speed: too coarse
        ("odometry_translation_std", -0.01),
        ("odometry_heading_std_rad", float("nan")),
        ("wall_radius_m", -0.001),
    ],
)
def test_config_rejects_bad_field_naming_it(field, value):
    with pytest.raises(ConfigError, match=field):
        RobotConfig(**{field: value})


def test_config_is_frozen_and_coerces_numbers():
    cfg = RobotConfig(radius_m=np.float64(0.2), physics_substeps=np.int64(20))
    assert type(cfg.radius_m) is float and type(cfg.physics_substeps) is int
    with pytest.raises(AttributeError):
        cfg.radius_m = 0.3  # type: ignore[misc]


# ---------------------------------------------------------------- kinematics


@pytest.mark.parametrize("theta", [0.0, 0.7, -2.5, math.pi])
def test_straight_drive_travels_speed_times_period(theta):
    robot = make(pose=(1.0, -2.0, theta))
    for k in range(1, 21):
        res = robot.step(0.3, 0.0)
        assert isinstance(res, StepResult)
        assert res.distance_m == pytest.approx(0.3 * T, abs=1e-9)
        assert not res.bumped
        x, y, th = robot.pose
        assert x == pytest.approx(1.0 + k * 0.3 * T * math.cos(theta), abs=1e-6)
        assert y == pytest.approx(-2.0 + k * 0.3 * T * math.sin(theta), abs=1e-6)
        assert math.remainder(th - theta, math.tau) == pytest.approx(0.0, abs=1e-12)


def test_reverse_drive_moves_backwards():
    robot = make(pose=(0.0, 0.0, math.pi / 2))
    robot.step(-0.4, 0.0)
    x, y, _ = robot.pose
    assert x == pytest.approx(0.0, abs=1e-9)
    assert y == pytest.approx(-0.4 * T, abs=1e-9)


@pytest.mark.parametrize("rate", [1.0, -0.5, W_MAX])
def test_turn_in_place_changes_heading_by_rate_times_period(rate):
    robot = make(pose=(0.5, 0.5, 0.1))
    heading = 0.1
    for _ in range(50):
        res = robot.step(0.0, rate)
        heading += rate * T
        assert res.pose.theta == pytest.approx(math.remainder(heading, math.tau), abs=1e-9)
        assert res.pose.x == pytest.approx(0.5, abs=1e-12)
        assert res.pose.y == pytest.approx(0.5, abs=1e-12)
        assert -math.pi <= res.pose.theta <= math.pi


def test_arc_curves_towards_the_turn():
    robot = make()
    for _ in range(5):
        robot.step(0.5, 1.0)
    x, y, theta = robot.pose
    assert theta == pytest.approx(5 * 1.0 * T)
    assert y > 0.0 and 0.0 < x < 5 * 0.5 * T  # a left turn
    assert math.hypot(x, y) == pytest.approx(2 * 0.5 * math.sin(0.5), rel=0.02)  # chord of arc


@pytest.mark.parametrize(
    ("cmd", "applied"),
    [
        ((10.0, 0.0), (V_MAX, 0.0)),
        ((-10.0, 0.0), (-V_MAX, 0.0)),
        ((0.0, 99.0), (0.0, W_MAX)),
        ((0.0, -99.0), (0.0, -W_MAX)),
        ((math.inf, -math.inf), (V_MAX, -W_MAX)),
    ],
)
def test_commands_beyond_limits_are_clipped(cmd, applied):
    robot = make()
    res = robot.step(*cmd)
    assert (res.linear_m_s, res.angular_rad_s) == applied
    reference = make()
    expected = reference.step(*applied)
    assert res.pose == pytest.approx(expected.pose, abs=1e-12)


def test_accepts_numpy_scalars_as_commands():
    robot = make()
    res = robot.step(np.float32(0.25), np.float64(0.0))
    assert res.distance_m == pytest.approx(0.25 * T, abs=1e-7)


# ---------------------------------------------------------------- walls and bumps


def _drive_and_check(robot: Robot, walls: np.ndarray, commands, xmax: float | None = None):
    """Step through commands; check free space and bump consistency at every step."""
    reach = R + robot.config.wall_radius_m
    bumps = 0
    after = wall_distance(robot.pose, walls)
    for v, w in commands:
        before = after
        res = robot.step(v, w)
        x, y, _ = res.pose
        assert 0.0 < x < 4.0 and 0.0 < y < 4.0
        if xmax is not None:
            assert x < xmax
        after = wall_distance(res.pose, walls)
        assert after >= R - TOL_M
        if after < reach - 1e-9:  # overlaps the wall skin at the end of the step
            assert res.bumped
        if before > reach + abs(res.linear_m_s) * T + 1e-3:  # cannot reach a wall in this step
            assert not res.bumped
        bumps += res.bumped
    return bumps


def test_no_bump_in_open_space():
    robot = make()
    for k in range(200):
        assert not robot.step(V_MAX, 0.3 * math.sin(k)).bumped
    assert not robot.bumped


def test_full_speed_into_wall_head_on_stays_in_free_space_and_bumps():
    robot = make(BOX, pose=(2.0, 2.0, 0.0))
    bumps = _drive_and_check(robot, BOX, [(V_MAX, 0.0)] * 1000)
    x, y, _ = robot.pose
    assert bumps >= 1000 - 20  # reaches the wall (1.83 m at 0.1 m/step) and then stays in contact
    assert robot.bumped
    assert x == pytest.approx(4.0 - R - robot.config.wall_radius_m, abs=2e-3)
    assert y == pytest.approx(2.0, abs=1e-9)  # head-on contact: no sliding, no spinning
    assert robot.pose.theta == pytest.approx(0.0, abs=1e-12)


@pytest.mark.episode
def test_full_speed_at_random_headings_into_box_walls():
    rng = np.random.default_rng(7)
    for theta in rng.uniform(-math.pi, math.pi, 20):
        robot = make(BOX, pose=(2.0, 2.0, theta))
        bumps = _drive_and_check(robot, BOX, [(V_MAX, 0.0)] * 1000)
        assert bumps > 900
        # It slides along the wall into a corner and stays there.
        x, y, _ = robot.pose
        assert min(x, 4.0 - x) < R + 0.02 and min(y, 4.0 - y) < R + 0.02


def test_random_driving_in_a_room_never_leaves_free_space():
    walls = thin_wall_room()
    rng = np.random.default_rng(3)
    robot = make(walls, pose=(1.0, 2.0, 0.0))
    commands = zip(
        rng.uniform(-0.2, 1.0, 1000) * V_MAX, rng.uniform(-1, 1, 1000) * W_MAX, strict=True
    )
    bumps = _drive_and_check(robot, walls, commands, xmax=2.0)
    assert bumps > 0


@pytest.mark.parametrize(
    ("thickness", "headings"),
    [
        (0.1, 5),
        pytest.param(0.1, 20, marks=pytest.mark.episode),
        pytest.param(0.05, 20, marks=pytest.mark.episode),
    ],
)
def test_thin_wall_is_never_crossed(thickness, headings):
    walls = thin_wall_room(thickness=thickness)
    rng = np.random.default_rng(11)
    # headings towards the wall (the quick loop's five are the first five of the twenty)
    for theta in rng.uniform(-0.48 * math.pi, 0.48 * math.pi, 20)[:headings]:
        robot = make(walls, pose=(1.2, float(rng.uniform(0.5, 3.5)), theta))
        bumps = _drive_and_check(robot, walls, [(V_MAX, 0.0)] * 1000, xmax=2.0 - R + TOL_M)
        assert bumps > 900


def test_a_reset_clears_the_bump_flag_to_false():
    robot = make(BOX, pose=(3.5, 2.0, 0.0))
    for _ in range(10):
        robot.step(V_MAX, 0.0)
    assert robot.bumped is True
    robot.reset((2.0, 2.0, 0.0))
    assert robot.bumped is False  # a bool, as step results carry it


def test_bump_flag_clears_after_leaving_the_wall():
    robot = make(BOX, pose=(3.5, 2.0, 0.0))
    for _ in range(10):
        robot.step(V_MAX, 0.0)
    assert robot.bumped
    robot.step(-V_MAX, 0.0)  # contact at the start of the step still counts
    robot.step(-V_MAX, 0.0)
    assert not robot.bumped


@settings(max_examples=25, deadline=None)
@given(
    start=st.tuples(st.floats(0.3, 1.7), st.floats(0.3, 3.7), st.floats(-math.pi, math.pi)),
    commands=st.lists(
        st.tuples(st.floats(-2.0, 2.0), st.floats(-5.0, 5.0)), min_size=1, max_size=60
    ),
)
def test_property_any_command_sequence_stays_in_free_space(start, commands):
    walls = thin_wall_room()
    robot = make(walls, pose=start)
    for v, w in commands * 3:
        res = robot.step(v, w)
        assert 0.0 < res.pose.x < 2.0 and 0.0 < res.pose.y < 4.0
        assert wall_distance(res.pose, walls) >= R - TOL_M


def wander(robot: Robot, n: int, seed: int) -> tuple[list, list[StepResult]]:
    """A bump-aware random walk: full speed with random turns; after a bump, back off turning."""
    rng = np.random.default_rng(seed)
    commands, results, backing = [], [], 0
    for _ in range(n):
        if backing:
            cmd, backing = (-0.5 * V_MAX, W_MAX), backing - 1
        else:
            cmd = (V_MAX, float(rng.uniform(-1, 1)) * W_MAX)
        commands.append(cmd)
        results.append(robot.step(*cmd))
        if results[-1].bumped and not backing:
            backing = int(rng.integers(1, 4))
    return commands, results


def test_open_space_shortcut_changes_nothing(monkeypatch):
    """Far from walls and, near them, along substeps that keep clear of every wall, the robot
    skips pymunk: the same poses, bumps and odometry as pymunk's every step."""
    near_clear = []
    original = robot_module.drive_substeps

    def counted(*args):
        out = original(*args)
        near_clear.append(len(args[-2]) > 0 and out[0])
        return out

    monkeypatch.setattr(robot_module, "drive_substeps", counted)
    walls = thin_wall_room()
    commands, fast_run = wander(make(walls, pose=(1.0, 1.0, 0.3)), 600, seed=8)
    monkeypatch.undo()
    monkeypatch.setattr(Robot, "_open_space_shortcut", False)
    slow = make(walls, pose=(1.0, 1.0, 0.3))
    assert [slow.step(v, w) for v, w in commands] == fast_run
    assert 50 < sum(r.bumped for r in fast_run) < 500  # both open space and contacts
    assert sum(near_clear) > 20  # and steps near a wall without a contact


# ---------------------------------------------------------------- odometry


def _random_commands(n: int, seed: int):
    rng = np.random.default_rng(seed)
    return list(zip(rng.uniform(0.0, 1.0, n) * V_MAX, rng.uniform(-1, 1, n) * W_MAX, strict=True))


def test_odometry_equals_true_pose_without_noise_even_when_sliding():
    walls = thin_wall_room()
    robot = make(walls, pose=(1.0, 1.0, 0.3))
    assert robot.odometry_pose == robot.pose
    bumps = 0
    for v, w in _random_commands(1000, 5):
        res = robot.step(v, w)
        bumps += res.bumped
        assert res.odometry_pose == pytest.approx(res.pose, abs=1e-9)
    assert bumps > 50  # the comparison covered wall contacts


def test_odometry_drifts_with_noise_and_is_deterministic_per_seed():
    noise = {"odometry_translation_std": 0.05, "odometry_heading_std_rad": 0.02}
    runs = {}
    for name, seed, cfg in [("a", 1, noise), ("b", 1, noise), ("c", 2, noise), ("clean", 1, {})]:
        robot = make(BOX, pose=(2.0, 2.0, 0.0), seed=seed, **cfg)
        runs[name] = [robot.step(v, w) for v, w in _random_commands(300, 9)]
    a, b, c, clean = runs["a"], runs["b"], runs["c"], runs["clean"]
    assert a == b  # same seed: identical
    assert [r.pose for r in a] == [r.pose for r in clean]  # noise never moves the robot
    drift = math.hypot(a[-1].odometry_pose.x - a[-1].pose.x, a[-1].odometry_pose.y - a[-1].pose.y)
    assert drift > 0.01
    assert a[-1].odometry_pose != c[-1].odometry_pose  # other seed: other drift


def test_odometry_noise_has_the_configured_scale():
    sigma_t, sigma_h = 0.1, 0.02
    robot = make(
        odometry_translation_std=sigma_t, odometry_heading_std_rad=sigma_h, seed=4, pose=(0, 0, 0)
    )
    d = V_MAX * T
    err_f, err_l, err_h = [], [], []
    for _ in range(2000):
        ox, oy, ot = robot.odometry_pose
        res = robot.step(V_MAX, 0.0)
        nx, ny, nt = res.odometry_pose
        dx, dy = nx - ox, ny - oy
        err_f.append(math.cos(ot) * dx + math.sin(ot) * dy - d)
        err_l.append(-math.sin(ot) * dx + math.cos(ot) * dy)
        err_h.append(math.remainder(nt - ot, math.tau))
    assert np.std(err_f) == pytest.approx(sigma_t * d, rel=0.1)
    assert np.std(err_l) == pytest.approx(sigma_t * d, rel=0.1)
    assert np.std(err_h) == pytest.approx(sigma_h, rel=0.1)
    assert abs(np.mean(err_f)) < 4 * sigma_t * d / math.sqrt(2000)


def test_zero_noise_draws_nothing_from_the_rng():
    rng = np.random.default_rng(0)
    robot = Robot(BOX, RobotConfig(), (2, 2, 0), rng)
    state = copy.deepcopy(rng.bit_generator.state)
    for v, w in _random_commands(20, 1):
        robot.step(v, w)
    assert rng.bit_generator.state == state


# ---------------------------------------------------------------- reset, pickling


def test_reset_teleports_and_restarts_odometry():
    robot = make(BOX, pose=(2.0, 2.0, 0.0), odometry_translation_std=0.1)
    for _ in range(30):
        robot.step(V_MAX, 0.2)
    pose = robot.reset((1.0, 3.0, 4.0))
    assert pose == pytest.approx((1.0, 3.0, 4.0 - math.tau))
    assert robot.pose == pose and robot.odometry_pose == pose
    assert not robot.bumped
    res = robot.step(0.2, 0.0)
    assert res.distance_m == pytest.approx(0.2 * T, abs=1e-9)  # no leftover velocity


@pytest.mark.parametrize("clone", ["pickle", "deepcopy"])
def test_copy_continues_identically(clone):
    walls = thin_wall_room()
    cfg = {"odometry_translation_std": 0.05, "odometry_heading_std_rad": 0.01}
    robot = make(walls, pose=(1.0, 2.0, 0.0), seed=3, **cfg)
    copied_in_contact = 0
    for k in range(12):
        wander(robot, 25, seed=k)
        twin = pickle.loads(pickle.dumps(robot)) if clone == "pickle" else copy.deepcopy(robot)
        assert twin.pose == robot.pose and twin.odometry_pose == robot.odometry_pose
        copied_in_contact += twin.bumped
        commands, results = wander(robot, 25, seed=100 + k)
        assert [twin.step(v, w) for v, w in commands] == results
    assert copied_in_contact > 0  # some copies were taken while touching a wall


# ---------------------------------------------------------------- bad input


@pytest.mark.parametrize("arg", ["linear_m_s", "angular_rad_s"])
@pytest.mark.parametrize("value", [float("nan"), np.nan, "fast", None])
def test_bad_command_raises_naming_the_argument(arg, value):
    robot = make()
    kwargs = {"linear_m_s": 0.1, "angular_rad_s": 0.1, arg: value}
    with pytest.raises(ConfigError, match=arg):
        robot.step(**kwargs)
    assert robot.pose == (0.0, 0.0, 0.0)  # nothing happened


@pytest.mark.parametrize(
    "walls",
    [
        np.zeros((3,)) + 1,
        np.zeros((2, 3)),
        np.zeros((2, 4, 1)),
        [[0, 0, 1, 1], [0, 0, 1]],
        [["a", "b", "c", "d"]],
    ],
)
def test_bad_wall_array_raises(walls):
    with pytest.raises(ConfigError, match="wall_segments"):
        Robot(walls, RobotConfig(), (5.0, 5.0, 0.0), np.random.default_rng(0))


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_non_finite_wall_raises_naming_the_row(bad):
    walls = BOX.copy()
    walls[2, 1] = bad
    with pytest.raises(ConfigError, match=r"wall_segments.*row 2"):
        Robot(walls, RobotConfig(), (2.0, 2.0, 0.0), np.random.default_rng(0))


def test_empty_wall_list_is_open_space():
    robot = Robot([], RobotConfig(), (0, 0, 0), np.random.default_rng(0))
    assert robot.wall_segments.shape == (0, 4)
    assert robot.step(V_MAX, 0).distance_m == pytest.approx(V_MAX * T)


@pytest.mark.parametrize(
    ("pose", "message"),
    [
        ((np.nan, 0.0, 0.0), "finite"),
        ((0.0, 0.0, np.inf), "finite"),
        ((0.0, 0.0), "shape"),
        ("abc", "pose"),
        ((2.0, 0.1, 0.0), "wall segment 0"),  # disc overlaps the bottom wall
    ],
)
def test_bad_pose_raises(pose, message):
    with pytest.raises(ConfigError, match=message):
        Robot(BOX, RobotConfig(), pose, np.random.default_rng(0))
    robot = make(BOX, pose=(2.0, 2.0, 0.0))
    with pytest.raises(ConfigError, match=message):
        robot.reset(pose)
    assert robot.pose == (2.0, 2.0, 0.0)


def test_bad_rng_and_config_raise():
    with pytest.raises(ConfigError, match="rng"):
        Robot(BOX, RobotConfig(odometry_heading_std_rad=0.01), (2, 2, 0), None)
    with pytest.raises(ConfigError, match="rng"):
        Robot(BOX, RobotConfig(), (2, 2, 0), np.random.RandomState(0))  # type: ignore[arg-type]
    with pytest.raises(ConfigError, match="config"):
        Robot(BOX, {"radius_m": 0.2}, (2, 2, 0), None)  # type: ignore[arg-type]
    assert Robot(BOX, None, (2, 2, 0), None).config == RobotConfig()  # noise-free: rng optional


@pytest.mark.parametrize(("n_walls", "bulk"), [(2048, False), (2049, True)])
def test_only_a_plan_of_more_than_bulk_vertices_walls_keeps_just_the_near_walls(n_walls, bulk):
    """``BULK_VERTICES`` walls (2,048) still go into pymunk all at once; one more and pymunk
    holds only the walls near the robot."""
    from sfw_gym.core.constants import BULK_VERTICES

    assert n_walls - BULK_VERTICES in (0, 1)
    x = np.linspace(-20.0, 20.0, n_walls + 1)
    walls = np.column_stack([x[:-1], np.full(n_walls, 3.0), x[1:], np.full(n_walls, 3.0)])
    robot = Robot(walls, RobotConfig(), (0.0, 0.0, 0.0))
    assert (robot._active_walls is not None) == bulk
    assert robot.step(V_MAX, 0.0).pose[0] > 0.0  # it drives either way
