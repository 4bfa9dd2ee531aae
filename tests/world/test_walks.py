"""Walks and surveys through a floorplan: physically valid paths that never jump."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from sfw_gym.core.errors import ConfigError
from sfw_gym.world import generate_floorplan
from sfw_gym.world.walks import survey, walk


@pytest.mark.parametrize("clearance_m", [0.19, 0.45])  # 0.45: doorways split the free space
@pytest.mark.parametrize("kind", ["walk", "survey"])
def test_a_path_keeps_its_clearance_and_never_jumps(kind, clearance_m):
    plan = generate_floorplan(2)
    if kind == "walk":
        path = walk(plan, np.random.default_rng(0), step_m=0.05, clearance_m=clearance_m)
    else:
        path = survey(plan, 0.5, step_m=0.05, clearance_m=clearance_m)
    assert len(path) > 100
    steps = np.linalg.norm(np.diff(path, axis=0), axis=1)
    assert steps.max() <= 0.05 + 1e-9  # consecutive points 5 cm apart at most
    region = plan.free_space.buffer(-clearance_m + 1e-6)
    assert shapely.contains_xy(region, path[:, 0], path[:, 1]).all()
    # every straight piece between samples stays in the free space (no wall is crossed)
    pieces = shapely.linestrings(np.stack([path[:-1], path[1:]], axis=1))
    assert shapely.within(pieces, plan.free_space).all()


def test_the_same_generator_walks_the_same_path_and_a_survey_covers_the_rooms():
    plan = generate_floorplan(3)
    a, b = (walk(plan, np.random.default_rng(7)) for _ in range(2))
    np.testing.assert_array_equal(a, b)
    path = survey(plan, 0.5)
    covered = shapely.buffer(shapely.linestrings(path), 0.5)
    assert covered.intersection(plan.free_space).area >= 0.9 * plan.free_space.area
    with pytest.raises(ConfigError, match=r"'gen-office-3': no free space is 5\.0 m from"):
        walk(plan, np.random.default_rng(0), clearance_m=5.0)
