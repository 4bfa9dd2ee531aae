"""Floorplans: exact wall counts, loading, saving, rasterisation, errors."""

from __future__ import annotations

import json

import numpy as np
import pytest
from shapely.geometry import LineString, Polygon

from sfw_gym.core.errors import FloorplanError
from sfw_gym.world.floorplan import Floorplan, floorplan_from_polygon, load_floorplan


def k(fp: Floorplan, a, b) -> int:
    return int(fp.count_walls(np.array([a], float), np.array([b], float))[0])


class TestCountWallsExact:
    def test_segment_across_one_wall(self, two_rooms):
        assert k(two_rooms, (2, 2), (8, 2)) == 1
        assert k(two_rooms, (2, 2), (8, 3.5)) == 1  # oblique, still below the doorway

    def test_segment_through_the_doorway_and_within_a_room(self, two_rooms):
        assert k(two_rooms, (2, 4.5), (8, 4.5)) == 0
        assert k(two_rooms, (1, 1), (4, 4)) == 0

    def test_touching_a_wall_end_is_not_a_crossing(self, two_rooms):
        # The line passes exactly through the notch's top corners (4.95, 4) and (5.05, 4).
        assert k(two_rooms, (2, 4), (8, 4)) == 0
        assert k(two_rooms, (4.5, 3.55), (5.5, 4.45)) == 1  # clips the wall's end for 6.7 cm
        assert k(two_rooms, (3.95, 3.0), (4.95, 4.0)) == 0  # ends exactly on the corner

    def test_notch_is_one_wall_not_two_boundary_crossings(self):
        # A HouseExpo-style notch: the outline goes in and out around a 0.1 m wall.
        notch = Polygon(
            [(0, 0), (6, 0), (6, 4), (3.05, 4), (3.05, 1), (2.95, 1), (2.95, 4), (0, 4)]
        )
        fp = floorplan_from_polygon(notch)
        assert k(fp, (1, 3), (5, 3)) == 1
        assert k(fp, (1, 0.5), (5, 0.5)) == 0  # below the notch's end

    def test_bevel_and_staircase_add_no_wall(self):
        # A 1 cm bevelled corner, and a diagonal wall cutting the top-right corner stored as a
        # 1 cm staircase (HouseExpo style): outer tooth corners on x + y = 6, inner on 5.99.
        stairs = []
        for i in range(200):
            stairs += [(4 - 0.01 * (i + 1), 2 + 0.01 * i), (4 - 0.01 * (i + 1), 2 + 0.01 * (i + 1))]
        ring = [(0.01, 0), (4, 0), (4, 2), *stairs[:-1], (2, 4), (0, 4), (0, 0.01)]
        fp = floorplan_from_polygon(Polygon(ring))
        assert k(fp, (0, 0.01), (0.01, 0)) == 0  # exactly along the bevel
        assert k(fp, (0, 0.01), (0, 3)) == 0  # along the wall, from the bevel's end
        # Parallel to the staircase, between its inner and outer corners: grazes every tooth.
        assert k(fp, (3.5, 2.495), (2.5, 3.495)) == 0
        # Straight through the diagonal wall: one wall.
        assert k(fp, (2.5, 2.5), (3.5, 3.5)) == 1

    def test_two_rooms_matrix(self, two_rooms):
        left = np.array([[1, 1], [2, 3], [4, 0.5]], float)
        right = np.array([[6, 1], [9, 3], [8, 0.5]], float)
        assert (two_rooms.count_walls(left, right) == 1).all()
        assert (two_rooms.count_walls(left, left[::-1]) == 0).all()

    def test_leaving_the_building_counts_the_outside_as_one_piece(self):
        ell = Polygon([(0, 0), (10, 0), (10, 3), (3, 3), (3, 10), (0, 10)])
        fp = floorplan_from_polygon(ell)
        assert k(fp, (9, 1.5), (1.5, 9)) == 1

    def test_broadcast_and_shapes(self, two_rooms):
        counts = two_rooms.count_walls(np.array([2.0, 2.0]), np.array([[8, 2], [3, 2]], float))
        assert counts.tolist() == [1, 0]
        with pytest.raises(FloorplanError, match="shape"):
            two_rooms.count_walls(np.zeros((3, 3)), np.zeros((3, 3)))


def _reference_count(fp: Floorplan, a, b, min_piece_m: float = 0.02) -> int:
    """Independent count with shapely: pieces of the segment outside the free space.

    The same physical definition as `count_walls` (pieces under 2 cm dropped, pieces separated
    by gaps under 2 cm merged) computed from shapely's geometric difference, not by crossings.
    """
    seg = LineString([a, b])
    outside = seg.difference(fp.free_space)
    pieces = [g for g in getattr(outside, "geoms", [outside]) if g.length >= min_piece_m]
    pos = sorted(
        (seg.project(g.interpolate(0)), seg.project(g.interpolate(1, normalized=True)))
        for g in pieces
    )
    pos = [tuple(sorted(p)) for p in pos]
    count, last_end = 0, -np.inf
    for start, end in pos:
        if start - last_end >= min_piece_m:
            count += 1
        last_end = max(last_end, end)
    return count


def test_count_walls_agrees_with_shapely_on_houseexpo(houseexpo_paths):
    rng = np.random.default_rng(2024)
    agree = total = 0
    for path in houseexpo_paths:
        fp = load_floorplan(path)
        xmin, ymin, xmax, ymax = fp.bounds
        pts = rng.uniform((xmin, ymin), (xmax, ymax), (4000, 2))
        pts = pts[fp.is_free(pts)][: 2 * (10_000 // len(houseexpo_paths) + 1)]
        a, b = pts[0::2], pts[1::2]
        n = min(len(a), len(b))
        ours = fp.count_walls(a[:n], b[:n])
        ref = np.array([_reference_count(fp, a[i], b[i]) for i in range(n)])
        agree += int((ours == ref).sum())
        total += n
    assert total >= 10_000
    assert agree / total >= 0.999, f"{agree}/{total} agree"


class TestLoadSave:
    def test_houseexpo_files_load(self, houseexpo_paths):
        for path in houseexpo_paths:
            fp = load_floorplan(path)
            data = json.loads(path.read_text())
            assert fp.name == data["id"] == path.stem
            assert 25.0 <= fp.area_m2 <= 321.0
            bx0, by0 = data["bbox"]["min"]
            bx1, by1 = data["bbox"]["max"]
            assert fp.free_space.bounds == pytest.approx((bx0, by0, bx1, by1), abs=1e-9)
            assert set(fp.edge_materials) == {"generic"}
            assert fp.rooms

    def test_sfw_json_round_trip_is_exact(self, tmp_path, houseexpo_paths):
        for path in houseexpo_paths[:3]:
            fp = load_floorplan(path)
            out = fp.save(tmp_path / f"{fp.name}.json")
            again = load_floorplan(out)
            assert np.array_equal(again.edges, fp.edges)
            assert again.edge_materials == fp.edge_materials
            assert again.footprint.equals_exact(fp.footprint, 0.0)
            assert again.rooms == fp.rooms and again.name == fp.name
            assert again.to_dict() == fp.to_dict()

    def test_round_trip_with_holes_and_materials(self, tmp_path):
        shell = [(0, 0), (8, 0), (8, 6), (0, 6)]
        hole = [(3, 2), (4, 2), (4, 3), (3, 3)]  # a pillar
        free = Polygon(shell, [hole])
        mats = ("brick",) * 4 + ("concrete",) * 4
        fp = Floorplan(free, Polygon([(-0.2, -0.2), (8.2, -0.2), (8.2, 6.2), (-0.2, 6.2)]), mats)
        again = load_floorplan(fp.save(tmp_path / "p.json"))
        assert again.edge_materials == mats and np.array_equal(again.edges, fp.edges)
        assert k(again, (1, 2.5), (7, 2.5)) == 1  # through the pillar

    def test_save_is_atomic_and_leaves_no_temp_files(self, tmp_path, two_rooms):
        two_rooms.save(tmp_path / "a.json")
        two_rooms.save(tmp_path / "a.json")
        assert [p.name for p in tmp_path.iterdir()] == ["a.json"]


BAD_INPUTS = {
    "not JSON": "{this is not json",
    "missing keys": json.dumps({"id": "x"}),
    "two vertices": json.dumps({"verts": [[0, 0], [1, 1]]}),
    "NaN": '{"verts": [[0, 0], [NaN, 0], [5, 5]]}',
    "infinite": '{"verts": [[0, 0], [Infinity, 0], [5, 5]]}',
    "self-intersecting": json.dumps({"verts": [[0, 0], [5, 5], [5, 0], [0, 5]]}),
    "zero area": json.dumps({"verts": [[0, 0], [5, 0], [10, 0]]}),
    "absurd size": json.dumps({"verts": [[0, 0], [9000, 0], [9000, 9000], [0, 9000]]}),
    "not a list": json.dumps({"verts": "abc"}),
    "strings": json.dumps({"verts": [["a", 0], [1, 0], [1, 1]]}),
    "array": "[1, 2, 3]",
    "sfw without materials": json.dumps(
        {
            "format": "sfw_gym.floorplan",
            "version": 1,
            "free_space": {"exterior": [[0, 0], [5, 0], [5, 5]]},
            "footprint": [[0, 0], [5, 0], [5, 5]],
        }
    ),
}


@pytest.mark.parametrize("problem", sorted(BAD_INPUTS))
def test_bad_files_raise_floorplan_error_naming_the_file(tmp_path, problem):
    path = tmp_path / "bad.json"
    path.write_text(BAD_INPUTS[problem])
    with pytest.raises(FloorplanError, match=r"bad\.json"):
        load_floorplan(path)


def test_missing_file_raises_floorplan_error(tmp_path):
    with pytest.raises(FloorplanError, match=r"nope\.json"):
        load_floorplan(tmp_path / "nope.json")


def test_unknown_material_and_mismatched_materials_are_rejected():
    square = Polygon([(0, 0), (4, 0), (4, 4), (0, 4)])
    footprint = square.buffer(0.2, join_style="mitre")
    with pytest.raises(FloorplanError, match="unknown wall material"):
        Floorplan(square, footprint, ("adamantium",) * 4)
    with pytest.raises(FloorplanError, match="edge materials"):
        Floorplan(square, footprint, ("brick",) * 3)


class TestRasterize:
    def test_two_rooms_grid(self, two_rooms):
        grid, origin = two_rooms.rasterize(0.05)
        assert origin == pytest.approx((-0.1, -0.1))
        assert grid.shape == (104, 204)  # 5.2 × 10.2 m
        row_of = lambda y: int((y - origin[1]) / 0.05)  # noqa: E731
        col_of = lambda x: int((x - origin[0]) / 0.05)  # noqa: E731
        assert grid[row_of(2), col_of(2)] == 255 and grid[row_of(2), col_of(8)] == 255
        assert grid[row_of(2), col_of(5.0)] == 0  # the interior wall
        assert grid[row_of(4.5), col_of(5.0)] == 255  # the doorway
        assert (grid[[0, -1], :] == 0).all() and (grid[:, [0, -1]] == 0).all()  # exterior walls
        assert not (grid == 127).any()  # a rectangle's mitred footprint leaves no outside cell

    @pytest.mark.parametrize("resolution", [0.1, 0.2, 0.3, 0.5])
    def test_thin_walls_survive_coarse_resolutions(self, two_rooms, resolution):
        grid, origin = two_rooms.rasterize(resolution)
        row = int((2.0 - origin[1]) / resolution)
        assert (grid[row] == 0).sum() >= 3  # left exterior, interior, right exterior wall

    def test_bad_resolution(self, two_rooms):
        with pytest.raises(FloorplanError, match="resolution_m"):
            two_rooms.rasterize(0.0)


def test_saved_files_get_the_usual_permissions(tmp_path, two_rooms):
    import os
    import stat

    path = two_rooms.save(tmp_path / "p.json")
    mask = os.umask(0)
    os.umask(mask)
    assert stat.S_IMODE(path.stat().st_mode) == 0o666 & ~mask


# ------------------------------------------------------------------------- routers and folders
def _hall() -> Floorplan:
    return floorplan_from_polygon(Polygon([(0, 0), (12, 0), (12, 8), (0, 8)]), name="hall")


def test_a_plan_s_routers_round_trip_and_a_plan_without_has_no_key(tmp_path):
    hall = _hall()
    assert hall.routers == () and "routers" not in hall.to_dict()
    data = hall.to_dict() | {"routers": [[3, 3], [9, 5.5]]}
    (tmp_path / "r.json").write_text(json.dumps(data))
    plan = load_floorplan(tmp_path / "r.json")
    assert plan.routers == ((3.0, 3.0), (9.0, 5.5))
    again = load_floorplan(plan.save(tmp_path / "again.json"))
    assert again.routers == plan.routers and again.to_dict() == plan.to_dict()


@pytest.mark.parametrize(
    ("routers", "message"),
    [
        ([[3, 3], [13, 5]], r"router 1 at \(13, 5\) is not in the free space"),
        ([[3, 3, 1]], r"routers\[0\] must be a list of 2 numbers"),
        ("3,3", "'routers' must be a list"),
        ([["a", 3]], r"routers\[0\] must hold numbers"),
    ],
)
def test_bad_routers_in_a_plan_are_refused_naming_the_file(tmp_path, routers, message):
    (tmp_path / "r.json").write_text(json.dumps(_hall().to_dict() | {"routers": routers}))
    with pytest.raises(FloorplanError, match=rf"r\.json: .*{message}"):
        load_floorplan(tmp_path / "r.json")


def test_floorplan_files_are_json_plans_and_ros_map_yamls_sorted(tmp_path):
    from sfw_gym.world.floorplan import floorplan_files

    for name in ("b.json", "a.yaml", "c.YML", "a.pgm", "notes.txt"):
        (tmp_path / name).write_text("")
    (tmp_path / "sub.json").mkdir()
    assert [p.name for p in floorplan_files(tmp_path)] == ["a.yaml", "b.json", "c.YML"]
    assert floorplan_files(tmp_path / "b.json") == [tmp_path / "b.json"]
    assert floorplan_files(tmp_path / "missing") == []


def test_chosen_routers_given_then_the_plan_s_then_the_default():
    from sfw_gym.world.floorplan import chosen_routers

    stored = Floorplan(
        _hall().free_space, _hall().footprint, _hall().edge_materials, routers=((3, 3),)
    )
    assert chosen_routers([[1, 1]], stored, 2) == [[1, 1]]
    assert chosen_routers(1, stored, 2) == 1
    assert chosen_routers(None, stored, 2) == [[3.0, 3.0]]
    assert chosen_routers(None, _hall(), 2) == 2
    assert chosen_routers(None, None) is None
