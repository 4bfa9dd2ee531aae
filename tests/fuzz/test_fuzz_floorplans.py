"""Fuzz: whatever goes into ``load_floorplan``, a Floorplan or one clean error comes out."""

from __future__ import annotations

import json

from hypothesis import given
from hypothesis import strategies as st

from sfw_gym.world.floorplan import Floorplan, load_floorplan
from tests.fuzz.conftest import outcome

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
    def load() -> None:
        assert isinstance(load_floorplan(data), Floorplan)

    outcome("floorplan JSON (dict)", load)


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


@given(st.lists(vertex, min_size=0, max_size=12))
def test_random_polygons_load_or_raise_floorplan_error(verts):
    _load_or_floorplan_error({"verts": verts})


@given(st.binary(max_size=200) | st.text(max_size=200).map(str.encode))
def test_garbage_bytes_raise_only_floorplan_error(tmp_path_factory, blob):
    path = tmp_path_factory.mktemp("fuzz") / "plan.json"
    path.write_bytes(blob)
    outcome("floorplan JSON (file)", lambda: load_floorplan(path), names="plan.json")


@given(
    st.sampled_from(["[", '{"verts": [']),
    st.integers(min_value=1, max_value=200_000),
    st.sampled_from(["1e400", "9" * 5000, "-0", "[1, 2]", "null", '"x"']),
)
def test_deep_nesting_and_huge_numbers_are_clean_errors(tmp_path_factory, opening, depth, leaf):
    path = tmp_path_factory.mktemp("fuzz") / "deep.json"
    closing = "]" * depth + ("}" if opening.startswith("{") else "")
    path.write_text(opening + "[" * depth + leaf + closing)
    outcome("floorplan JSON (file)", lambda: load_floorplan(path), names="deep.json")


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
