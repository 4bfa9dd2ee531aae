"""An angular index of wall edges per router: the radio's wall crossings without every edge.

Every radio ray starts at a router. Seen from the router, an edge spans an arc of directions,
and a line through the router meets the edge only in a direction (mod π) inside that arc. The
index cuts the directions [0, π) into ``n_buckets`` buckets and lists, per router and bucket,
the edges whose arc, widened by ``ANGLE_MARGIN_RAD`` on each side, meets the bucket, in
ascending order. An edge passing within ``NEAR_ROUTER_M`` of the router is in every bucket.

A ray then tests only its bucket's edges with `wall_crossing._walls_crossed`, the brute force's
own code. This gives the same result bit for bit, because the bucket holds every edge the brute
force could use, far inside the margin:
- every edge the ray's supporting line crosses, those before the router included (their parity
  says whether the router is inside). The sign tests round by about 1e-15 of an endpoint's
  distance from the router, so such an edge has a point within about 1e-15 rad of the line;
- every edge within 1e-9 m of a piece's midpoint at least ``NEAR_START_M`` (2 mm) from the
  router: within 1e-9 m / 2 mm = 5e-7 rad of the line (a midpoint nearer the router is checked
  against every edge).
The bucket keeps the brute force's edge order, so its sorted crossings (ties included) come out
the same. ``tests/world/test_wall_index.py`` checks this on random and degenerate rays.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from sfw_gym.world.wall_crossing import _walls_crossed, edge_offset

#: Buckets of directions over [0, π) per router.
DEFAULT_BUCKETS = 256
#: Each edge's arc is widened by this on both sides (the module doc's bounds are ≤ 5e-7 rad).
ANGLE_MARGIN_RAD = 1e-5
#: Edges passing this close to a router are in all its buckets (their arcs are ill-conditioned).
NEAR_ROUTER_M = 1e-3


@njit(cache=True)
def _distance_to_edge(edges, e, x, y):
    """Distance from (x, y) to edge ``e`` (a closed segment)."""
    cx, cy = edge_offset(edges, e, x, y)
    return math.hypot(cx, cy)


@njit(cache=True)
def _bucket_span(edges, e, ax, ay, n_buckets):
    """The first bucket of edge ``e``'s widened arc seen from (ax, ay), and how many buckets it
    covers (``n_buckets``: all)."""
    if _distance_to_edge(edges, e, ax, ay) < NEAR_ROUTER_M:
        return 0, n_buckets
    tp = math.atan2(edges[e, 1] - ay, edges[e, 0] - ax)
    tq = math.atan2(edges[e, 3] - ay, edges[e, 2] - ax)
    sweep = tq - tp  # the arc from p to q the edge sweeps: shorter than π, a is off the edge
    if sweep > math.pi:
        sweep -= 2.0 * math.pi
    elif sweep < -math.pi:
        sweep += 2.0 * math.pi
    lo = min(tp, tp + sweep) - ANGLE_MARGIN_RAD
    hi = max(tp, tp + sweep) + ANGLE_MARGIN_RAD
    width = math.pi / n_buckets
    first = math.floor(lo / width)
    count = math.floor(hi / width) - first + 1
    if count >= n_buckets:
        return 0, n_buckets
    return first % n_buckets, count


@njit(cache=True)
def build_wall_index(edges, routers, n_buckets):
    """The angular index of ``edges`` (E, 4) around each of ``routers`` (R, 2).

    Returns:
        ``starts`` (R, n_buckets + 1) int64 and ``edge_ids`` int32: router r's bucket b lists
        ``edge_ids[starts[r, b]:starts[r, b + 1]]``, ascending.
    """
    n_r = routers.shape[0]
    n_e = edges.shape[0]
    starts = np.zeros((n_r, n_buckets + 1), np.int64)
    first = np.empty((n_r, n_e), np.int64)
    count = np.empty((n_r, n_e), np.int64)
    total = 0
    for r in range(n_r):
        sizes = np.zeros(n_buckets, np.int64)
        for e in range(n_e):
            first[r, e], count[r, e] = _bucket_span(
                edges, e, routers[r, 0], routers[r, 1], n_buckets
            )
            for k in range(count[r, e]):
                sizes[(first[r, e] + k) % n_buckets] += 1
        starts[r, 0] = total
        for b in range(n_buckets):
            starts[r, b + 1] = starts[r, b] + sizes[b]
        total = starts[r, n_buckets]
    edge_ids = np.empty(total, np.int32)
    for r in range(n_r):
        fill = starts[r, :n_buckets].copy()
        for e in range(n_e):  # ascending e: each bucket comes out sorted
            for k in range(count[r, e]):
                b = (first[r, e] + k) % n_buckets
                edge_ids[fill[b]] = e
                fill[b] += 1
    return starts, edge_ids


@njit(cache=True)
def bucket_of(dx, dy, n_buckets):
    """The bucket of a ray's direction (dx, dy), mod π."""
    width = math.pi / n_buckets
    return math.floor(math.atan2(dy, dx) / width) % n_buckets


@njit(cache=True)
def cross_from_router(
    edges, edge_loss, starts, edge_ids, all_edges, r, ax, ay, bx, by, min_piece_m, ts, ids
):
    """`wall_crossing._cross_one` for a segment from router ``r`` at (ax, ay) (the point the
    index was built around) to (bx, by), testing only its bucket's edges."""
    n_buckets = starts.shape[1] - 1
    b = bucket_of(bx - ax, by - ay, n_buckets)
    return _walls_crossed(
        edges, edge_loss, edge_ids, starts[r, b], starts[r, b + 1], all_edges, ax, ay, bx, by,
        min_piece_m, ts, ids,
    )  # fmt: skip
