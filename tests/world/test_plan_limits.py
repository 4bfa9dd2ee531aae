"""Plans at their limits: many vertices (a size guard, bulk geometry that keeps what the plan
means) and segments with NaN ends."""

from __future__ import annotations

import json

import gymnasium as gym
import numpy as np
import pytest
import shapely

import sfw_gym  # noqa: F401  (registration)
from sfw_gym.core.errors import FloorplanError
from sfw_gym.world import load_floorplan
from sfw_gym.world.floorplan import MAX_VERTICES
from sfw_gym.world.routers import ROUTER_CLEARANCE_M, place_routers


def serrated(n: int, tmp_path) -> str:
    theta = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    r = 8.0 + 0.05 * (np.arange(n) % 2)  # 5 cm teeth: they survive a 1 cm simplification
    path = tmp_path / f"serrated_{n}.json"
    verts = np.column_stack([8.5 + r * np.cos(theta), 8.5 + r * np.sin(theta)])
    path.write_text(json.dumps({"id": "serrated", "verts": verts.tolist()}))
    return str(path)


@pytest.mark.episode
def test_a_many_vertex_plan_keeps_its_shape_and_places_routers_clear_of_walls(tmp_path):
    path = serrated(6000, tmp_path)
    plan = load_floorplan(path)
    exact = shapely.Polygon(json.loads(open(path).read())["verts"])
    assert len(plan.edges) > 5000  # the teeth are kept
    assert plan.free_space.symmetric_difference(exact).area < 0.01 * exact.length
    assert plan.footprint.contains(plan.free_space)
    # an exterior wall at least 0.1 m thick everywhere, at most 0.34 m
    assert plan.footprint.buffer(1e-6).contains(exact.buffer(0.1))
    assert exact.buffer(0.34).contains(plan.footprint)
    routers = place_routers(plan, 2, np.random.default_rng(0))
    for x, y in routers:
        point = shapely.Point(x, y)
        assert plan.free_space.contains(point)
        assert plan.free_space.boundary.distance(point) >= ROUTER_CLEARANCE_M
    env = gym.make("SfW-Explore-v0")
    obs, _ = env.reset(seed=0, options={"floorplan": path})
    assert env.observation_space.contains(obs)


def test_a_plan_over_the_vertex_limit_is_refused_by_name(tmp_path):
    path = serrated(MAX_VERTICES + 10, tmp_path)
    with pytest.raises(FloorplanError, match=r"serrated_50010\.json: .* has 50,011 vertices, over"):
        load_floorplan(path)


def test_counting_walls_from_a_nan_point_is_an_error_not_zero(two_rooms):
    with pytest.raises(FloorplanError, match=r"must be finite; rows \[1\] are not"):
        two_rooms.count_walls(np.array([[1.0, 1.0], [np.nan, 1.0]]), np.array([9.0, 1.0]))


def test_a_bulk_plan_robot_keeps_clear_of_every_wall_and_its_copies_continue_exactly():
    """Over BULK_VERTICES walls pymunk holds only those near the robot, chosen again as it
    moves: the robot must still stop at every wall, and a pickled copy (taken at any step)
    must drive on exactly like the original."""
    import pickle

    from sfw_gym.core.constants import BULK_VERTICES
    from sfw_gym.world import generate_floorplan
    from sfw_gym.world.robot import Robot, RobotConfig

    plan = generate_floorplan(3)
    pieces = int(np.ceil((BULK_VERTICES + 1) / len(plan.edges)))
    t = np.linspace(0.0, 1.0, pieces + 1)[:, None]
    a, b = plan.edges[:, None, :2], plan.edges[:, None, 2:]
    walls = np.concatenate([a + (b - a) * t[:-1], a + (b - a) * t[1:]], axis=2).reshape(-1, 4)
    assert len(walls) > BULK_VERTICES
    config = RobotConfig()
    for trial in range(6):
        rng = np.random.default_rng(trial)
        pose = plan.free_space.buffer(-0.3).representative_point()
        robot = Robot(walls, config, (pose.x, pose.y, rng.uniform(-3, 3)))
        commands = rng.uniform([-0.5, -1.5], [0.5, 1.5], (400, 2))
        commands[rng.random(400) < 0.6, 0] = 0.5  # mostly full speed ahead: many contacts
        copy_at, copy = int(rng.integers(50, 300)), None
        bumps = 0
        for i, (v, w) in enumerate(commands):
            step = robot.step(v, w)
            bumps += step.bumped
            if copy is not None:
                assert copy.step(v, w) == step, f"trial {trial}: the copy left at step {i}"
            elif i == copy_at:
                copy = pickle.loads(pickle.dumps(robot))
            centre = np.array(step.pose[:2])
            clearance = np.min(np.hypot(*(centre - _closest(centre, walls)).T))
            assert clearance >= config.radius_m, f"trial {trial} step {i}: into a wall"
        assert bumps > 10  # the drive did meet walls
        assert len(robot._active_walls) < len(walls) / 2  # pymunk holds the nearby walls only


def _closest(p: np.ndarray, walls: np.ndarray) -> np.ndarray:
    a, d = walls[:, :2], walls[:, 2:] - walls[:, :2]
    t = np.clip(np.einsum("ij,ij->i", p - a, d) / np.einsum("ij,ij->i", d, d), 0.0, 1.0)
    return a + t[:, None] * d
