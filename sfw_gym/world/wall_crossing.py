"""Compiled wall counting: how many distinct walls a straight segment crosses.

The free space is a polygon (with holes); everything outside it is wall. A segment's k-value is the
number of maximal pieces of the segment that lie outside the free space. Crossings of the segment's
supporting line with the polygon's edges use the half-open rule of crossing-number point-in-polygon
tests, so vertices and collinear edges are handled as if the line were shifted infinitesimally: no
special cases, and parity stays consistent.

Two tolerances make the count physical rather than combinatorial:
- outside pieces shorter than ``min_piece_m`` are ignored (clipping a 1 cm bevel, grazing a
  staircase tooth, touching a wall's end);
- outside pieces separated by an inside gap shorter than ``min_piece_m`` are one wall (a staircase
  tooth inside a diagonal wall).
The boundary itself is free space: a segment running along a wall face crosses nothing.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

#: Outside pieces (and inside gaps) shorter than this are no walls (bevels 1 cm, walls ≥ 10 cm).
DEFAULT_MIN_PIECE_M = 0.02
_CHUNK = 512  # segments per parallel work item
#: A piece's midpoint closer than this to the segment's start is checked against every edge
#: (an index's edges near the line are only those this far along it; see `_walls_crossed`).
NEAR_START_M = 2e-3


@njit(cache=True, inline="always")
def _insert_sorted(ts: np.ndarray, ids: np.ndarray, n: int, t: float, edge: int) -> None:
    """Insert (t, edge) into the first n entries of ts/ids, keeping ts ascending."""
    j = n
    while j > 0 and ts[j - 1] > t:
        ts[j] = ts[j - 1]
        ids[j] = ids[j - 1]
        j -= 1
    ts[j] = t
    ids[j] = edge


@njit(cache=True)
def edge_offset(edges, e, x, y):
    """The vector from (x, y) to the nearest point of edge ``e`` (a closed segment)."""
    px = edges[e, 0]
    py = edges[e, 1]
    ex = edges[e, 2] - px
    ey = edges[e, 3] - py
    len2 = ex * ex + ey * ey
    u = 0.0 if len2 == 0.0 else min(1.0, max(0.0, ((x - px) * ex + (y - py) * ey) / len2))
    return px + u * ex - x, py + u * ey - y


@njit(cache=True)
def _on_boundary(edges, near, lo, hi, x, y):
    """Whether (x, y) lies on one of the edges ``near[lo:hi]`` (within 1e-9 m): a segment running
    along a wall face."""
    for j in range(lo, hi):
        cx, cy = edge_offset(edges, near[j], x, y)
        if cx * cx + cy * cy < 1e-18:
            return True
    return False


@njit(cache=True)
def _walls_crossed(
    edges, edge_loss, near, lo, hi, all_edges, ax, ay, bx, by, min_piece_m, ts, ids
) -> tuple[int, float]:
    """Walls crossed by segment a→b and their summed loss (loss of each wall's entry edge),
    testing only the edges ``near[lo:hi]`` (ascending).

    With every edge (``near = all_edges``) this is the brute force, `_cross_one`. A spatial
    index (`sfw_gym.world.wall_index`) may pass fewer: every edge the supporting line crosses,
    and every edge within 1e-9 m of the line farther than ``NEAR_START_M`` from a (the check
    of a piece's midpoint closer to a tests ``all_edges``). The edges come in the brute force's
    order and meet its arithmetic, so the result is the same bit for bit.
    """
    dx = bx - ax
    dy = by - ay
    length2 = dx * dx + dy * dy
    if length2 <= 0.0:
        return 0, 0.0
    length = np.sqrt(length2)
    n_before = 0  # crossings of the supporting line before a: their parity says if a is inside
    n = 0  # crossings with t in [0, 1], sorted
    for j in range(lo, hi):
        e = near[j]
        px = edges[e, 0]
        py = edges[e, 1]
        qx = edges[e, 2]
        qy = edges[e, 3]
        sp = dx * (py - ay) - dy * (px - ax)
        sq = dx * (qy - ay) - dy * (qx - ax)
        if (sp > 0.0) == (sq > 0.0):
            continue
        u = sp / (sp - sq)
        ix = px + u * (qx - px)
        iy = py + u * (qy - py)
        t = ((ix - ax) * dx + (iy - ay) * dy) / length2
        if t < 0.0:
            n_before += 1
        elif t <= 1.0:
            _insert_sorted(ts, ids, n, t, e)
            n += 1
    inside = (n_before % 2) == 1
    count = 0
    loss = 0.0
    last_wall_end = -1.0e300  # metres along the segment where the last counted wall ended
    start = 0.0
    start_edge = -1
    for i in range(n + 1):
        end = ts[i] if i < n else 1.0
        if not inside:
            piece_start_m = start * length
            piece_end_m = end * length
            mid = 0.5 * (start + end)
            if piece_end_m - piece_start_m >= min_piece_m:
                x = ax + mid * dx
                y = ay + mid * dy
                if mid * length < NEAR_START_M:
                    on_face = _on_boundary(edges, all_edges, 0, all_edges.shape[0], x, y)
                else:
                    on_face = _on_boundary(edges, near, lo, hi, x, y)
                if not on_face:
                    if piece_start_m - last_wall_end >= min_piece_m:
                        count += 1
                        # The wall's material: the edge the segment entered by, else the one it
                        # left by.
                        e = start_edge if start_edge >= 0 else (ids[i] if i < n else -1)
                        if e >= 0:
                            loss += edge_loss[e]
                    last_wall_end = piece_end_m
        if i < n:
            start = ts[i]
            start_edge = ids[i]
            inside = not inside
    return count, loss


@njit(cache=True)
def _cross_one(edges, edge_loss, all_edges, ax, ay, bx, by, min_piece_m, ts, ids):
    """The brute force: `_walls_crossed` testing every edge (``all_edges``: 0..E-1)."""
    return _walls_crossed(
        edges, edge_loss, all_edges, 0, all_edges.shape[0], all_edges, ax, ay, bx, by,
        min_piece_m, ts, ids,
    )  # fmt: skip


@njit(cache=True)
def _cross_range(edges, edge_loss, a, b, min_piece_m, counts, losses, lo, hi):
    ts = np.empty(edges.shape[0] + 1, dtype=np.float64)  # scratch, once per range
    ids = np.empty(edges.shape[0] + 1, dtype=np.int64)
    all_edges = np.arange(edges.shape[0])
    for i in range(lo, hi):
        counts[i], losses[i] = _cross_one(
            edges, edge_loss, all_edges, a[i, 0], a[i, 1], b[i, 0], b[i, 1], min_piece_m, ts, ids
        )


@njit(cache=True)
def cross_walls(edges, edge_loss, a, b, min_piece_m):
    """Count walls and sum wall losses for M segments a[i]→b[i] (serial: for a few segments).

    Args:
        edges: (E, 4) free-space boundary segments [x0, y0, x1, y1].
        edge_loss: (E,) loss in dB of the wall behind each edge.
        a: (M, 2) segment starts.
        b: (M, 2) segment ends.
        min_piece_m: pieces and gaps shorter than this are ignored (see module docstring).

    Returns:
        (M,) int32 wall counts and (M,) float64 summed losses in dB.
    """
    counts = np.zeros(a.shape[0], dtype=np.int32)
    losses = np.zeros(a.shape[0], dtype=np.float64)
    _cross_range(edges, edge_loss, a, b, min_piece_m, counts, losses, 0, a.shape[0])
    return counts, losses


@njit(cache=True, parallel=True)
def cross_walls_parallel(edges, edge_loss, a, b, min_piece_m):
    """`cross_walls` over all cores, for many segments (heat maps, benchmarks)."""
    m = a.shape[0]
    counts = np.zeros(m, dtype=np.int32)
    losses = np.zeros(m, dtype=np.float64)
    n_chunks = (m + _CHUNK - 1) // _CHUNK
    for c in prange(n_chunks):
        _cross_range(
            edges,
            edge_loss,
            a,
            b,
            min_piece_m,
            counts,
            losses,
            c * _CHUNK,
            min(m, (c + 1) * _CHUNK),
        )
    return counts, losses
