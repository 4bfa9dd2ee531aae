"""Property-based: whatever goes into `load_floorplan`, only `FloorplanError` comes out."""

from __future__ import annotations

import json

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from sfw_gym.core.errors import FloorplanError
from sfw_gym.world.floorplan import Floorplan, load_floorplan

numbers = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-(10**6), max_value=10**6),
    st.floats(min_value=-50, max_value=50),
)
json_values = st.recursive(
    st.none() | st.booleans() | numbers | st.text(max_size=5),
    lambda inner: (
        st.lists(inner, max_size=6) | st.dictionaries(st.text(max_size=6), inner, max_size=4)
    ),
    max_leaves=20,
)
vertex = st.tuples(st.floats(-30, 30), st.floats(-30, 30)).map(list)


def _load_or_floorplan_error(data: object) -> None:
    try:
        fp = load_floorplan(data) if isinstance(data, dict) else None
    except FloorplanError:
        return
    assert fp is None or isinstance(fp, Floorplan)


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.dictionaries(
        st.sampled_from(
            [
                "verts",
                "id",
                "format",
                "version",
                "free_space",
                "footprint",
                "edge_materials",
                "rooms",
                "room_category",
            ]
        ),
        json_values,
        max_size=6,
    )
)
def test_garbage_dicts_raise_only_floorplan_error(data):
    _load_or_floorplan_error(data)


@settings(max_examples=300, deadline=None)
@given(st.lists(vertex, min_size=0, max_size=12))
def test_random_polygons_load_or_raise_floorplan_error(verts):
    _load_or_floorplan_error({"verts": verts})


@settings(max_examples=150, deadline=None)
@given(st.binary(max_size=200) | st.text(max_size=200).map(str.encode))
def test_garbage_bytes_raise_only_floorplan_error(tmp_path_factory, blob):
    path = tmp_path_factory.mktemp("fuzz") / "plan.json"
    path.write_bytes(blob)
    try:
        load_floorplan(path)
    except FloorplanError as exc:
        assert "plan.json" in str(exc)


@settings(max_examples=100, deadline=None)
@given(st.lists(vertex, min_size=3, max_size=10))
def test_sfw_format_with_random_rings(verts):
    data = {
        "format": "sfw_gym.floorplan",
        "version": 1,
        "free_space": {"exterior": verts},
        "footprint": verts,
        "edge_materials": ["generic"] * len(verts),
    }
    _load_or_floorplan_error(json.loads(json.dumps(data)))
