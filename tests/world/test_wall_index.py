"""The radio's angular wall index gives the brute force's crossings bit for bit, degenerate rays
included (through vertices, along edges, zero length, on the plan's boundary)."""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import Polygon

from sfw_gym.world.floorplan import Floorplan, floorplan_from_polygon
from sfw_gym.world.generator import generate_floorplan
from sfw_gym.world.wall_crossing import DEFAULT_MIN_PIECE_M, NEAR_START_M, _cross_one
from sfw_gym.world.wall_index import DEFAULT_BUCKETS, build_wall_index, cross_from_router


@lru_cache
def plans() -> tuple[Floorplan, ...]:
    """Generated plans, and hand-made ones with collinear edges, a hole, a comb and a diagonal
    staircase."""
    two_rooms = Polygon(
        [(0, 0), (4.95, 0), (4.95, 4), (5.05, 4), (5.05, 0), (10, 0), (10, 5), (0, 5)]
    )
    collinear = Polygon(  # edges split at collinear vertices, and a pillar on the same lines
        [(0, 0), (2, 0), (4, 0), (6, 0), (6, 3), (6, 6), (3, 6), (0, 6), (0, 3)],
        [[(2, 2), (4, 2), (4, 4), (2, 4)]],
    )
    comb = [(0.0, 0.0)]
    for i in range(4):
        x = 2.0 + 2.0 * i
        comb += [(x, 0.0), (x, 4.0), (x + 0.1, 4.0), (x + 0.1, 0.0)]
    comb += [(12.0, 0.0), (12.0, 5.0), (0.0, 5.0)]
    stairs = [(0.0, 0.0), (8.0, 0.0), (8.0, 8.0)]
    for i in range(8, 0, -1):  # a diagonal wall drawn as 0.5 m teeth
        stairs += [(i - 0.5, float(i)), (i - 0.5, i - 0.5)]
    stairs += [(0.0, 0.5)]
    hand_made = [Polygon(p) for p in (comb, stairs)] + [two_rooms, collinear]
    return (
        *map(floorplan_from_polygon, hand_made),
        *(generate_floorplan(seed) for seed in range(3)),
    )


def points(draw, plan: Floorplan, edges: np.ndarray) -> tuple[float, float]:
    """A point anywhere, on a vertex, on an edge, on an edge's line beyond it, or on the plan's
    bounding box."""
    x0, y0, x1, y1 = plan.bounds
    kind = draw(st.sampled_from(["anywhere", "vertex", "on edge", "edge line", "bounds"]))
    e = edges[draw(st.integers(0, len(edges) - 1))]
    if kind == "anywhere":
        return (draw(st.floats(x0 - 1, x1 + 1)), draw(st.floats(y0 - 1, y1 + 1)))
    if kind == "vertex":
        return (float(e[0]), float(e[1])) if draw(st.booleans()) else (float(e[2]), float(e[3]))
    if kind in ("on edge", "edge line"):
        u = draw(st.sampled_from([0.5, 0.25, 1e-12]) | st.floats(0, 1))
        if kind == "edge line":
            u = draw(st.sampled_from([-1.0, 2.0, -1e-9, 1 + 1e-9]) | st.floats(-3, 4))
        return (e[0] + u * (e[2] - e[0]), e[1] + u * (e[3] - e[1]))
    side = draw(st.integers(0, 3))
    s = draw(st.floats(0, 1))
    return [(x0 + s * (x1 - x0), y0), (x0 + s * (x1 - x0), y1), (x0, y0 + s * (y1 - y0)),
            (x1, y0 + s * (y1 - y0))][side]  # fmt: skip


@settings(max_examples=600, deadline=None)
@given(st.data())
def test_index_crossings_equal_the_brute_force(data):
    plan = data.draw(st.sampled_from(plans()))
    edges = plan.edges
    loss = 1.0 + np.arange(len(edges)) * 0.37  # a different loss per edge: it names the edge
    a = points(data.draw, plan, edges)
    end = data.draw(st.sampled_from(["point", "same", "near", "through a vertex"]))
    if end == "point":
        b = points(data.draw, plan, edges)
    elif end == "same":
        b = a
    elif end == "near":  # a midpoint within NEAR_START_M of the router: checked on every edge
        step = data.draw(st.floats(1e-9, 3 * NEAR_START_M))
        b = (a[0] + step, a[1] + data.draw(st.floats(-1, 1)) * step)
    else:  # the ray through a vertex, ending past it
        e = edges[data.draw(st.integers(0, len(edges) - 1))]
        scale = data.draw(st.sampled_from([1.0, 2.0, 0.5]) | st.floats(0.1, 3))
        b = (a[0] + scale * (e[0] - a[0]), a[1] + scale * (e[1] - a[1]))
    n_buckets = data.draw(st.sampled_from([DEFAULT_BUCKETS, 1, 7, 4096]))
    min_piece = data.draw(st.sampled_from([DEFAULT_MIN_PIECE_M, 0.0]))
    all_edges = np.arange(len(edges))
    scratch = np.empty(len(edges) + 1), np.empty(len(edges) + 1, np.int64)
    brute = _cross_one(edges, loss, all_edges, *a, *b, min_piece, *scratch)
    starts, edge_ids = build_wall_index(edges, np.array([a, (0.5, 0.5)]), n_buckets)
    indexed = cross_from_router(
        edges, loss, starts, edge_ids, all_edges, 0, *a, *b, min_piece, *scratch
    )
    assert indexed == brute


def test_buckets_list_few_edges_in_ascending_order():
    plan = generate_floorplan(0)
    routers = np.array([[2.0, 2.0], [5.0, 7.0]])
    starts, edge_ids = build_wall_index(plan.edges, routers, DEFAULT_BUCKETS)
    sizes = np.diff(starts, axis=1)
    assert sizes.mean() < 0.25 * len(plan.edges)
    for r in range(len(routers)):
        for b in range(DEFAULT_BUCKETS):
            bucket = edge_ids[starts[r, b] : starts[r, b + 1]]
            assert (np.diff(bucket) > 0).all()
