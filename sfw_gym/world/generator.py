"""Procedural floorplans: apartments and offices with rooms, corridors, doorways and wall materials.

The package's embedded default world. A plan is laid out as axis-aligned room *tiles* that exactly
cover the building's interior (tile sides are wall centre lines), on a 5 cm grid in integer
centimetres, so every shapely operation is exact and no slivers arise: apartments ("hall" or "bsp"
style) and offices (a central corridor), :mod:`sfw_gym.world.layouts` lays them out.

An L-shaped footprint removes one corner room. Every pair of adjacent rooms is separated by a wall
rectangle (centred on the shared side, one thickness and material per straight wall line),
except "open" pairs (hall↔living room, kitchen↔living room). Doorways are gaps in those
rectangles, chosen by a breadth-first spanning tree from the hub (bathrooms are leaves) plus a few
extra doors that close loops, so every room is reachable. Free space = interior minus the union
of the wall rectangles; the footprint is the interior grown by the exterior wall. Each free-space
edge takes the material of the wall it faces (its midpoint pushed 3 cm outward). Extra doors
close loops, each around an island of walls: a hole in the free-space polygon.
"""

from __future__ import annotations

import math
import numbers
from collections import deque
from dataclasses import dataclass
from typing import Any

import numpy as np
import shapely
from shapely.geometry import Polygon
from shapely.geometry.polygon import orient

from sfw_gym.core.config import Config, setting
from sfw_gym.core.errors import ConfigError, FloorplanError
from sfw_gym.world.floorplan import Floorplan, Room
from sfw_gym.world.layouts import (
    BATH,
    GRID_CM,
    Layout,
    cut_corner,
    random_layout,
    snap,
    symmetry,
    tile_area,
    uniform_snap,
)

#: Kinds of building the generator makes ("random" picks one from the seed).
KINDS = ("apartment", "office")
#: Footprint shapes ("random" picks one from the seed).
SHAPES = ("rectangle", "L")
#: Materials allowed for the exterior walls.
EXTERIOR_MATERIALS = ("brick", "concrete")
#: Free-area range (m²) of generated plans.
MIN_AREA_M2, MAX_AREA_M2 = 40.0, 200.0
#: Radius (m) of the robot disc that must pass every doorway.
ROBOT_RADIUS_M = 0.17
#: Range (m) accepted for ``door_width_m``.
MIN_DOOR_M, MAX_DOOR_M = 0.8, 1.2


@dataclass(frozen=True)
class GeneratorConfig(Config):
    """The overrides :func:`generate_floorplan` takes (None / "random": drawn from the seed)."""

    kind: str = setting("random", choices=(*KINDS, "random"))
    area_m2: float | None = setting(None, optional=True, ge=MIN_AREA_M2, le=MAX_AREA_M2)
    shape: str = setting("random", choices=(*SHAPES, "random"))
    exterior_material: str | None = setting(None, optional=True, choices=EXTERIOR_MATERIALS)
    door_width_m: float | None = setting(None, optional=True, ge=MIN_DOOR_M, le=MAX_DOOR_M)
    extra_door_prob: float | None = setting(None, optional=True, ge=0.0, le=1.0)
    name: str | None = None

    def validate(self) -> None:
        if self.name is not None and not isinstance(self.name, str):
            raise ConfigError(f"GeneratorConfig.name must be a string or None, got {self.name!r}")


_DOOR_CLEAR = 20  # cm: doorway jamb to the wall line's junction (centre line)
_MIN_DOOR = 80  # cm
_PUSH = 3  # cm: edge midpoints pushed into the facing wall (less than half the thinnest wall)
_MAX_ATTEMPTS = 200
_MIN_ISLAND = 50  # cm: shortest free-standing wall (between two doorways) allowed
_FREE_FRACTION = {"apartment": 0.955, "office": 0.965}  # free area / interior area (measured)
# Interior wall materials: probability and thickness choices (cm, even so half is an integer).
_INTERIOR = {
    "apartment": (("drywall", 0.75, (10, 12)), ("brick", 0.25, (12, 14))),
    "office": (("drywall", 0.65, (10, 12)), ("glass", 0.2, (10,)), ("brick", 0.15, (12, 14))),
}


# ------------------------------------------------------------------------------------------ API
def generate_floorplan(seed: int, **params: Any) -> Floorplan:
    """Generate a realistic apartment or office floorplan, deterministically from ``seed``.

    Args:
        seed: non-negative integer; the only source of randomness (``np.random.default_rng``).
        **params: optional overrides:

            - ``kind``: "apartment", "office" or "random" (default: drawn from the seed).
            - ``area_m2``: target free area, 40–200 m² (default: drawn; apartments ~42–160,
              offices ~60–195). The result lies within ±15 % of it and always in 40–200 m².
            - ``shape``: "rectangle", "L" or "random" (default: drawn, about one in three is
              L-shaped).
            - ``exterior_material``: "brick" or "concrete" (default: drawn).
            - ``door_width_m``: doorway width, 0.8–1.2 m, rounded to 5 cm (default: drawn per door,
              0.8–1.0 m); a doorway in a short wall is narrowed to fit, never below 0.8 m.
            - ``extra_door_prob``: probability, 0–1, that two adjacent rooms already connected
              otherwise get a door too (loops); default 0.2 (apartments), 0.1 (offices).
            - ``name``: the plan's name (default ``"gen-<kind>-<seed>"``).

    Returns:
        A valid :class:`Floorplan`: one free-space polygon, labelled rooms, every free cell
        reachable and every doorway passable by a robot of radius 0.17 m.

    Raises:
        ConfigError: a bad seed or parameter (naming it), or an unknown parameter.
    """
    p = _validate(seed, params)
    rng = np.random.default_rng(int(seed))
    # Top-level draws always happen, so an explicit value leaves the rest of the stream unchanged.
    kind = KINDS[int(rng.integers(len(KINDS)))]
    shape = "L" if rng.random() < 0.35 else "rectangle"
    u_material = rng.random()
    kind = kind if p.kind == "random" else p.kind
    ext_material = EXTERIOR_MATERIALS[int(u_material < (0.6 if kind == "office" else 0.4))]
    drawn_area = math.exp(rng.uniform(*np.log((42.0, 160.0) if kind == "apartment" else (60, 195))))
    shape = shape if p.shape == "random" else p.shape
    ext_material = p.exterior_material or ext_material
    area = float(p.area_m2 if p.area_m2 is not None else drawn_area)
    extra = p.extra_door_prob
    extra = (0.2 if kind == "apartment" else 0.1) if extra is None else float(extra)
    door_cm = None if p.door_width_m is None else snap(100.0 * p.door_width_m)
    name = p.name if p.name is not None else f"gen-{kind}-{int(seed)}"

    lo, hi = max(MIN_AREA_M2, 0.85 * area), min(MAX_AREA_M2, 1.15 * area)
    aim = float(np.clip(area, MIN_AREA_M2 * 1.04, MAX_AREA_M2 / 1.04))
    gross = aim / _FREE_FRACTION[kind] * 1e4  # interior area, cm²
    inflate = rng.uniform(1.08, 1.16)  # L-shapes: the removed corner room's share, learnt below
    for _ in range(_MAX_ATTEMPTS):
        if shape == "L":
            layout = random_layout(rng, kind, gross * inflate)
            layout = cut_corner(layout, gross) if layout is not None else None
            if layout is not None:
                got = layout.width * layout.height - tile_area(layout.cut)  # type: ignore[arg-type]
                inflate = float(np.clip(inflate * gross / got, 1.0, 1.6))
                if abs(got / gross - 1.0) > 0.08:
                    continue
        else:
            layout = random_layout(rng, kind, gross)
        if layout is None:
            continue
        layout = symmetry(layout, int(rng.integers(8)))  # any orientation, mirrored or not
        plan = _build(rng, layout, kind, ext_material, door_cm, extra, name)
        if plan is not None and lo <= plan.area_m2 <= hi:
            return plan
    raise FloorplanError(  # pragma: no cover - never seen over many thousand seeds
        f"generate_floorplan(seed={seed}): no valid plan after {_MAX_ATTEMPTS} attempts"
    )


def _validate(seed: Any, params: dict[str, Any]) -> GeneratorConfig:
    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral) or seed < 0:
        raise ConfigError(f"seed must be a non-negative integer, got {seed!r}")
    return GeneratorConfig.from_dict(params, "generate_floorplan")


# --------------------------------------------------------------------------------------- layouts
# -------------------------------------------------------------------------------------- geometry
def _adjacencies(
    tiles: list[tuple[int, int, int, int]],
) -> list[tuple[int, int, bool, int, int, int]]:
    """(i, j, vertical, coord, s0, s1) for every pair of tiles sharing a side of positive length."""
    t = np.asarray(tiles, dtype=np.int64)
    x0, y0, x1, y1 = (t[:, k] for k in range(4))
    out = []
    for vertical, lo, hi, a0, a1 in ((True, x0, x1, y0, y1), (False, y0, y1, x0, x1)):
        touch = hi[:, None] == lo[None, :]  # tile i's high side on tile j's low side
        s0 = np.maximum(a0[:, None], a0[None, :])
        s1 = np.minimum(a1[:, None], a1[None, :])
        for i, j in zip(*np.nonzero(touch & (s1 > s0)), strict=True):
            a, b = (int(i), int(j)) if i < j else (int(j), int(i))
            out.append((a, b, vertical, int(hi[i]), int(s0[i, j]), int(s1[i, j])))
    return out


def _spanning_doors(
    rng: np.random.Generator,
    layout: Layout,
    adj: list[tuple[int, int, bool, int, int, int]],
    extra: float,
) -> tuple[list[int], list[int]] | None:
    """Adjacency indices that get a doorway: a BFS tree from the hub, and extra doors."""
    n = len(layout.tiles)
    nbrs: list[list[tuple[int, int]]] = [[] for _ in range(n)]
    for k, (i, j, _, _, s0, s1) in enumerate(adj):
        if (i, j) in layout.open_pairs or s1 - s0 >= _MIN_DOOR + 2 * _DOOR_CLEAR:
            nbrs[i].append((j, k))
            nbrs[j].append((i, k))
    seen = [False] * n
    doors: list[int] = []
    queue: deque[int] = deque()
    late: deque[int] = deque()  # bathrooms: expanded only if nothing else reaches a room

    partners: list[list[int]] = [[] for _ in range(n)]
    for i, j in layout.open_pairs:
        partners[i].append(j)
        partners[j].append(i)

    def visit(v: int) -> None:
        """Mark v and the rooms open to it (no door needed between them) as reached."""
        stack = [v]
        while stack:
            u = stack.pop()
            if not seen[u]:
                seen[u] = True
                (late if layout.labels[u] == BATH else queue).append(u)
                stack += partners[u]

    visit(layout.hub)
    while queue or late:
        u = queue.popleft() if queue else late.popleft()
        for o in rng.permutation(len(nbrs[u])):
            v, k = nbrs[u][o]
            if not seen[v]:
                doors.append(k)
                visit(v)
    if not all(seen):
        return None
    tree, extra_doors = set(doors), []
    for k, (i, j, *_rest) in enumerate(adj):
        if k in tree or (i, j) in layout.open_pairs or BATH in (layout.labels[i], layout.labels[j]):
            continue
        if adj[k][5] - adj[k][4] >= _MIN_DOOR + 2 * _DOOR_CLEAR and rng.random() < extra:
            extra_doors.append(k)
    return doors, extra_doors


def _build(
    rng: np.random.Generator,
    layout: Layout,
    kind: str,
    ext_material: str,
    door_cm: int | None,
    extra: float,
    name: str,
) -> Floorplan | None:
    adj = _adjacencies(layout.tiles)
    doors = _spanning_doors(rng, layout, adj, extra)
    if doors is None:
        return None
    walls = [k for k, a in enumerate(adj) if (a[0], a[1]) not in layout.open_pairs]
    seg = np.array([adj[k][2:] for k in walls], dtype=np.int64)  # vertical, coord, s0, s1
    vert, coord, s0, s1 = seg[:, 0].astype(bool), seg[:, 1], seg[:, 2], seg[:, 3]
    n = len(walls)

    # One material and thickness per straight wall line (touching collinear segments).
    chain = np.zeros(n, dtype=np.int64)
    order = np.lexsort((s0, coord, vert))
    c, end = -1, None
    for k in order:
        key = (vert[k], coord[k])
        if end is None or key != end[0] or s0[k] > end[1]:
            c += 1
            end = (key, s1[k])
        else:
            end = (key, max(end[1], s1[k]))
        chain[k] = c
    choices = _INTERIOR[kind]
    probs = np.array([p for _, p, _ in choices])
    picks = rng.choice(len(choices), size=c + 1, p=probs / probs.sum())
    thick = np.array([int(rng.choice(choices[q][2])) for q in picks], dtype=np.int64)
    materials = [choices[q][0] for q in picks]
    half = thick[chain] // 2

    # Extend each segment end into the perpendicular walls meeting there (fills L-corners);
    # no extension on the building's boundary.
    ext = np.zeros((n, 2), dtype=np.int64)
    for e, s in enumerate((s0, s1)):
        hit = (
            (vert[None, :] != vert[:, None])
            & (coord[None, :] == s[:, None])
            & (s0[None, :] <= coord[:, None])
            & (s1[None, :] >= coord[:, None])
        )
        ext[:, e] = np.where(hit, half[None, :], 0).max(axis=1)
    px = np.where(vert[:, None], coord[:, None], np.stack([s0, s1], 1))
    py = np.where(vert[:, None], np.stack([s0, s1], 1), coord[:, None])
    on_edge = _on_boundary(layout, px, py)
    ext[on_edge] = 0

    # Doorways of the spanning tree, redrawn until every wall piece is still anchored to the
    # exterior through other walls (no free-standing pillar); then the extra doors, each of which
    # closes a loop around an island of walls, kept unless an island is shorter than _MIN_ISLAND.
    tree, extra_doors = doors
    seg_of = {k: m for m, k in enumerate(walls)}
    span = np.stack([s0 - ext[:, 0], s1 + ext[:, 1]], 1).tolist()
    for _ in range(10):
        gaps = {
            seg_of[k]: _door_gap(rng, int(s0[seg_of[k]]), int(s1[seg_of[k]]), door_cm) for k in tree
        }
        if not _islands(px, py, on_edge, span, gaps):
            break
    else:
        return None
    for k in extra_doors:
        m = seg_of[k]
        for _ in range(2):
            trial = {**gaps, m: _door_gap(rng, int(s0[m]), int(s1[m]), door_cm)}
            if min(_islands(px, py, on_edge, span, trial), default=math.inf) >= _MIN_ISLAND:
                gaps = trial
                break

    # Wall rectangles with the doorway gaps.
    rects: list[tuple[int, int, int, int]] = []
    rect_mat: list[str] = []
    for m in range(n):
        a, b = int(s0[m] - ext[m, 0]), int(s1[m] + ext[m, 1])
        pieces = [(a, gaps[m][0]), (gaps[m][1], b)] if m in gaps else [(a, b)]
        hv, cv = int(half[m]), int(coord[m])
        for p0, p1 in pieces:
            rects.append((cv - hv, p0, cv + hv, p1) if vert[m] else (p0, cv - hv, p1, cv + hv))
            rect_mat.append(materials[chain[m]])

    region = shapely.box(0, 0, layout.width, layout.height)
    if layout.cut is not None:
        region = region.difference(shapely.box(*layout.cut))
    r = np.asarray(rects, dtype=np.float64)
    wall_union = shapely.union_all(shapely.box(r[:, 0], r[:, 1], r[:, 2], r[:, 3]))
    free = shapely.simplify(region.difference(wall_union), 0)
    if not isinstance(free, Polygon) or not free.is_valid:
        return None
    eroded = free.buffer(-100 * ROBOT_RADIUS_M, quad_segs=2)
    if not isinstance(eroded, Polygon) or eroded.is_empty:
        return None
    free = orient(free, sign=1.0)  # exterior CCW, holes CW: free space on each edge's left

    # Material of each free-space edge: the wall its midpoint, pushed outward, lands in.
    pts = [np.asarray(ring.coords) for ring in (free.exterior, *free.interiors)]
    starts = np.vstack([q[:-1] for q in pts])
    d = np.vstack([q[1:] - q[:-1] for q in pts])
    normal = np.stack([d[:, 1], -d[:, 0]], 1) / np.hypot(d[:, 0], d[:, 1])[:, None]
    probe = starts + 0.5 * d + _PUSH * normal
    inside = _in_region(layout, probe[:, 0], probe[:, 1])
    hit = (
        (probe[:, 0:1] >= r[None, :, 0])
        & (probe[:, 0:1] <= r[None, :, 2])
        & (probe[:, 1:2] >= r[None, :, 1])
        & (probe[:, 1:2] <= r[None, :, 3])
    )
    if not hit[inside].any(axis=1).all():
        return None  # an edge facing no wall: should not happen
    first = hit.argmax(axis=1)
    edge_materials = tuple(
        rect_mat[first[e]] if inside[e] else ext_material for e in range(len(probe))
    )

    # Geometry in metres, footprint's lower-left corner at the origin.
    t_ext = int(rng.integers(20, 31))
    footprint = region.buffer(t_ext, join_style="mitre")
    to_m = lambda xy: (xy + t_ext) / 100.0  # noqa: E731
    rooms = _rooms(layout, vert, coord, s0, s1, half, t_ext)
    return Floorplan(
        shapely.transform(free, to_m),
        shapely.transform(footprint, to_m),
        edge_materials,
        name=name,
        rooms=rooms,
    )


def _door_gap(rng: np.random.Generator, s0: int, s1: int, door_cm: int | None) -> tuple[int, int]:
    """A doorway (d0, d1) in the wall segment [s0, s1], clear of the junctions at its ends."""
    dw = door_cm if door_cm is not None else uniform_snap(rng, 80, 100)
    dw = min(dw, (s1 - s0 - 2 * _DOOR_CLEAR) // GRID_CM * GRID_CM)
    lo, hi = s0 + _DOOR_CLEAR, s1 - _DOOR_CLEAR - dw
    if rng.random() < 0.6:  # near a corner, as doors usually are
        near = (lo, min(hi, lo + 30)) if rng.random() < 0.5 else (max(lo, hi - 30), hi)
        d0 = uniform_snap(rng, *near)
    else:
        d0 = uniform_snap(rng, lo, hi)
    d0 = min(max(d0, lo), hi)
    return d0, d0 + dw


def _islands(
    px: np.ndarray,
    py: np.ndarray,
    on_edge: np.ndarray,
    span: list[list[int]],
    gaps: dict[int, tuple[int, int]],
) -> list[int]:
    """Lengths (cm) of the groups of wall pieces not connected to the exterior wall.

    Piece ``2m + e`` is the piece of segment m holding its end e (one piece, ``2m``, without a
    doorway); pieces meet where segment ends coincide; ends on the boundary meet the exterior.
    """
    n = len(px)
    xs, ys, edge = px.tolist(), py.tolist(), on_edge.tolist()
    parent = list(range(2 * n + 1))  # the last node is the exterior

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    at: dict[tuple[int, int], int] = {}
    length = [0] * (2 * n)
    for m in range(n):
        a, b = span[m]
        if m in gaps:
            length[2 * m], length[2 * m + 1] = gaps[m][0] - a, b - gaps[m][1]
        else:
            length[2 * m] = b - a
        for e in (0, 1):
            node = 2 * m + (e if m in gaps else 0)
            parent[find(node)] = find(at.setdefault((xs[m][e], ys[m][e]), node))
            if edge[m][e]:
                parent[find(node)] = find(2 * n)
    root = find(2 * n)
    islands: dict[int, int] = {}
    for node in range(2 * n):
        if length[node] and find(node) != root:
            islands[find(node)] = islands.get(find(node), 0) + length[node]
    return list(islands.values())


def _in_region(layout: Layout, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    inside = (x > 0) & (x < layout.width) & (y > 0) & (y < layout.height)
    if layout.cut is not None:
        cx0, cy0, cx1, cy1 = layout.cut
        inside &= ~((x >= cx0) & (x <= cx1) & (y >= cy0) & (y <= cy1))
    return inside


def _on_boundary(layout: Layout, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    on = (x == 0) | (x == layout.width) | (y == 0) | (y == layout.height)
    if layout.cut is not None:
        cx0, cy0, cx1, cy1 = layout.cut
        in_x, in_y = (x >= cx0) & (x <= cx1), (y >= cy0) & (y <= cy1)
        on |= (in_x & ((y == cy0) | (y == cy1))) | (in_y & ((x == cx0) | (x == cx1)))
    return on


def _rooms(
    layout: Layout,
    vert: np.ndarray,
    coord: np.ndarray,
    s0: np.ndarray,
    s1: np.ndarray,
    half: np.ndarray,
    offset: int,
) -> tuple[Room, ...]:
    """Room boxes in metres: each tile shrunk by the half-thickness of the walls on its sides."""
    rooms = []
    for (x0, y0, x1, y1), label in zip(layout.tiles, layout.labels, strict=True):
        shrink = []
        for vertical, c, a, b in (
            (1, x0, y0, y1),
            (0, y0, x0, x1),
            (1, x1, y0, y1),
            (0, y1, x0, x1),
        ):
            on = (vert == bool(vertical)) & (coord == c) & (s0 < b) & (s1 > a)
            shrink.append(int(half[on].max()) if on.any() else 0)
        box = (x0 + shrink[0], y0 + shrink[1], x1 - shrink[2], y1 - shrink[3])
        rooms.append(Room(label, tuple((v + offset) / 100.0 for v in box)))  # type: ignore[arg-type]
    return tuple(rooms)
