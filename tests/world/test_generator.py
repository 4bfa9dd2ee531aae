"""The procedural floorplan generator: validity, reachability, realism, determinism, parameters."""

from __future__ import annotations

import functools
import itertools
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy import ndimage
from shapely.geometry import Point, Polygon

from sfw_gym.core.errors import ConfigError
from sfw_gym.world.floorplan import MATERIALS, Floorplan, load_floorplan
from sfw_gym.world.generator import ROBOT_RADIUS_M, generate_floorplan

KINDS = ("apartment", "office")
SEEDS = range(50)
EXTERIOR = {"brick", "concrete"}


@functools.cache
def plan(seed: int, kind: str = "random", **params: object) -> Floorplan:
    return generate_floorplan(seed, kind=kind, **params)


def plans(kind: str) -> list[Floorplan]:
    return [plan(s, kind) for s in SEEDS]


def check_reachable(fp: Floorplan) -> None:
    """Free cells 4-connected at 0.1 m; the robot's free space connected and in every room."""
    grid, _ = fp.rasterize(0.1)
    _, n = ndimage.label(grid == 255)  # default structure: 4-connectivity
    assert n == 1, f"{fp.name}: {n} components of free cells at 0.1 m"
    eroded = fp.free_space.buffer(-ROBOT_RADIUS_M)
    assert isinstance(eroded, Polygon) and not eroded.is_empty, f"{fp.name}: robot space split"
    for room in fp.rooms:
        x0, y0, x1, y1 = room.box
        assert eroded.contains(Point((x0 + x1) / 2, (y0 + y1) / 2)), (
            f"{fp.name}: {room} unreachable"
        )


def outward_probe(fp: Floorplan, dist: float) -> np.ndarray:
    """Each free-space edge's midpoint moved ``dist`` metres to the side away from free space."""
    e = fp.edges
    mid = 0.5 * (e[:, :2] + e[:, 2:])
    d = e[:, 2:] - e[:, :2]
    normal = np.stack([d[:, 1], -d[:, 0]], 1) / np.hypot(d[:, 0], d[:, 1])[:, None]
    side = mid + 1e-3 * normal
    normal[fp.is_free(side)] *= -1  # rings may run either way: point away from the free side
    return mid + dist * normal


@pytest.mark.parametrize("kind", KINDS)
class TestGeneratedPlans:
    def test_valid_plans_in_the_area_range(self, kind):
        for fp in plans(kind):
            assert isinstance(fp, Floorplan)
            assert isinstance(fp.free_space, Polygon) and fp.free_space.is_valid
            assert 40.0 <= fp.area_m2 <= 200.0, (fp.name, fp.area_m2)
            assert fp.name.startswith(f"gen-{kind}-")
            assert len(fp.edge_materials) == len(fp.edges)

    def test_every_free_cell_and_room_reachable(self, kind):
        for fp in plans(kind):
            check_reachable(fp)

    def test_interior_walls_separate_rooms(self, kind):
        deep = 0
        for fp in plans(kind):
            boxes = np.array([r.box for r in fp.rooms])
            centres = 0.5 * (boxes[:, :2] + boxes[:, 2:])
            i, j = np.array(list(itertools.combinations(range(len(centres)), 2))).T
            k = fp.count_walls(centres[i], centres[j])
            assert k.max() >= 1, fp.name
            deep += k.max() >= 2  # some room pairs lie two or more walls apart
        assert deep >= 0.8 * len(SEEDS)

    def test_materials_exterior_brick_or_concrete(self, kind):
        seen: set[str] = set()
        for fp in plans(kind):
            assert set(fp.edge_materials) <= set(MATERIALS)
            mats = np.array(fp.edge_materials)
            # A point 0.35 m behind an exterior-facing edge lies outside the footprint (exterior
            # walls are 0.2–0.3 m thick); behind an interior one it is still inside.
            outside = ~fp.footprint.contains(
                [Point(p) for p in outward_probe(fp, 0.35)]  # type: ignore[arg-type]
            )
            assert outside.any() and (~outside).any()
            assert set(mats[outside]) <= EXTERIOR, fp.name
            assert len(set(mats[outside])) == 1, fp.name  # one exterior material per building
            seen |= set(mats[~outside])
        assert "drywall" in seen and "brick" in seen

    def test_wall_thicknesses(self, kind):
        for fp in plans(kind):
            ext = fp.footprint.exterior.distance(fp.free_space.exterior)
            assert 0.2 - 1e-9 <= ext <= 0.3 + 1e-9, (fp.name, ext)
            # Interior walls: walking straight through the wall behind an edge, free space comes
            # back after 0.10–0.15 m (most edges) and never sooner (no sliver walls).
            e = fp.edges
            mid = 0.5 * (e[:, :2] + e[:, 2:])
            steps = np.arange(1, 61) * 0.005
            ray = (
                mid[:, None, :] + steps[None, :, None] * (outward_probe(fp, 1.0) - mid)[:, None, :]
            )
            free = fp.is_free(ray)
            back = steps[free.argmax(axis=1)][free.any(axis=1)]
            assert back.min() >= 0.1 - 1e-6, fp.name
            assert np.mean(back <= 0.155) > 0.85, fp.name
            coords = np.vstack([fp.edges[:, :2], fp.edges[:, 2:]])
            assert np.allclose(coords, np.round(coords, 2))  # on the 1 cm grid
            lengths = np.hypot(*(fp.edges[:, 2:] - fp.edges[:, :2]).T)
            assert lengths.min() >= 0.01 - 1e-9, fp.name

    def test_rooms_labelled_and_realistic(self, kind):
        for fp in plans(kind):
            labels = [r.label for r in fp.rooms]
            assert "Bathroom" in labels
            if kind == "office":
                assert "Corridor" in labels and "Office" in labels
            else:
                assert "Living_Room" in labels
                assert "Bedroom" in labels or "Office" in labels
            for r in fp.rooms:
                x0, y0, x1, y1 = r.box
                assert fp.footprint.contains(Point((x0 + x1) / 2, (y0 + y1) / 2))
                assert min(x1 - x0, y1 - y0) >= 1.2, (fp.name, r)
                if r.label == "Bathroom":
                    assert (x1 - x0) * (y1 - y0) <= 14.0, (fp.name, r)

    def test_deterministic_per_seed(self, kind):
        for seed in (0, 7, 31):
            a, b = generate_floorplan(seed, kind=kind), generate_floorplan(seed, kind=kind)
            assert np.array_equal(a.edges, b.edges)
            assert a.edge_materials == b.edge_materials
            assert a.rooms == b.rooms and a.name == b.name
            assert a.footprint.equals_exact(b.footprint, 0.0)
        signatures = {(fp.edges.tobytes(), fp.edge_materials) for fp in plans(kind)}
        assert len(signatures) == len(SEEDS)

    def test_save_load_round_trip(self, kind, tmp_path):
        for seed in (1, 2):
            fp = plan(seed, kind)
            back = load_floorplan(fp.save(tmp_path / f"{fp.name}.json"))
            assert np.array_equal(back.edges, fp.edges)
            assert back.edge_materials == fp.edge_materials
            assert back.rooms == fp.rooms and back.name == fp.name
            a, b = np.array([[1.0, 1.0]]), np.array([[6.0, 4.0]])
            assert np.array_equal(back.count_walls(a, b), fp.count_walls(a, b))


def test_random_kind_draws_both_kinds():
    names = {plan(s).name.split("-")[1] for s in range(20)}
    assert names == set(KINDS)


def test_parameters_are_honoured():
    for seed in range(10):
        fp = plan(seed, "apartment", shape="L", area_m2=90.0, exterior_material="concrete")
        assert len(fp.footprint.exterior.coords) - 1 == 6  # an L
        assert 0.85 * 90 <= fp.area_m2 <= 1.15 * 90
        rect = plan(seed, "office", shape="rectangle", area_m2=150.0)
        assert len(rect.footprint.exterior.coords) - 1 == 4
        assert 0.85 * 150 <= rect.area_m2 <= 1.15 * 150
        outside = ~fp.footprint.contains([Point(p) for p in outward_probe(fp, 0.35)])  # type: ignore[arg-type]
        assert set(np.array(fp.edge_materials)[outside]) == {"concrete"}
    for area in (40.0, 200.0):
        for kind, shape in itertools.product(KINDS, ("rectangle", "L")):
            fp = generate_floorplan(3, kind=kind, shape=shape, area_m2=area)
            assert 40.0 <= fp.area_m2 <= 200.0
    assert generate_floorplan(5, name="mine").name == "mine"


def test_wide_doors_and_no_extra_doors_still_reachable():
    for seed in range(5):
        check_reachable(generate_floorplan(seed, door_width_m=1.2, extra_door_prob=1.0))
        check_reachable(generate_floorplan(seed, door_width_m=0.8, extra_door_prob=0.0))


def test_extra_doors_make_loops():
    """Without extra doors the free space is simply connected (the doors form a tree); extra
    doors close loops, each around an island of walls (a hole in the free-space polygon)."""
    loops = 0
    for seed in range(20):
        assert not generate_floorplan(seed, extra_door_prob=0.0).free_space.interiors
        loops += len(generate_floorplan(seed, extra_door_prob=1.0).free_space.interiors) > 0
    assert loops >= 15


@pytest.mark.parametrize(
    ("params", "word"),
    [
        ({"kind": "castle"}, "kind"),
        ({"shape": "round"}, "shape"),
        ({"area_m2": 10.0}, "area_m2"),
        ({"area_m2": 500}, "area_m2"),
        ({"area_m2": math.nan}, "area_m2"),
        ({"area_m2": "big"}, "area_m2"),
        ({"area_m2": True}, "area_m2"),
        ({"exterior_material": "drywall"}, "exterior_material"),
        ({"door_width_m": 0.3}, "door_width_m"),
        ({"extra_door_prob": 2.0}, "extra_door_prob"),
        ({"name": 5}, "name"),
        ({"rooms": 4}, "valid"),
    ],
)
def test_bad_params_raise_config_error(params, word):
    with pytest.raises(ConfigError, match=word):
        generate_floorplan(0, **params)


@pytest.mark.parametrize("seed", [-1, 1.5, "1", True, None])
def test_bad_seed_raises_config_error(seed):
    with pytest.raises(ConfigError, match="seed"):
        generate_floorplan(seed)


def test_unknown_param_lists_valid_ones():
    with pytest.raises(ConfigError) as info:
        generate_floorplan(0, size=3)
    for key in ("kind", "area_m2", "shape", "door_width_m"):
        assert key in str(info.value)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**63 - 1))
def test_any_seed_gives_a_reachable_plan(seed):
    fp = generate_floorplan(seed)
    assert 40.0 <= fp.area_m2 <= 200.0
    check_reachable(fp)
