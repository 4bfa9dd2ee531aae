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
