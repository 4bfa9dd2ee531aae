"""Room layouts of the procedural floorplans (:mod:`sfw_gym.world.generator`): axis-aligned room
*tiles* that exactly cover a building's interior (tile sides are wall centre lines), on a 5 cm grid
in integer centimetres.

- **apartment**, "hall" style: a living zone (optionally split into living room and kitchen) at one
  end, a hall along the long axis with bands of rooms (bedrooms, bathroom, …) on both sides, and
  optionally a full-depth room closing the hall. "bsp" style: a binary space partition of the
  interior, the living room being the hub.
- **office**: a central corridor with offices on both sides, optionally meeting rooms closing its
  ends; one bathroom and often a kitchen among the band rooms.

A layout can be turned into any of the rectangle's 8 orientations (:func:`symmetry`), and lose a
corner room for an L-shaped footprint (:func:`cut_corner`). The walls, doorways and materials are
the generator's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

GRID_CM = 5  # cm: room tiles snap to this grid
BATH, LIVING, KITCHEN, CORRIDOR = "Bathroom", "Living_Room", "Kitchen", "Corridor"


@dataclass
class Layout:
    """Room tiles in integer cm (x0, y0, x1, y1) covering [0, width] × [0, height] minus ``cut``."""

    tiles: list[tuple[int, int, int, int]]
    labels: list[str]
    hub: int
    width: int
    height: int
    open_pairs: set[tuple[int, int]] = field(default_factory=set)
    cut: tuple[int, int, int, int] | None = None


def snap(v: float) -> int:
    return round(v / GRID_CM) * GRID_CM


def uniform_snap(rng: np.random.Generator, lo: float, hi: float) -> int:
    """A grid value drawn uniformly in [lo, hi] (grid-rounded bounds)."""
    a, b = math.ceil(lo / GRID_CM), math.floor(hi / GRID_CM)
    return int(rng.integers(a, max(a, b) + 1)) * GRID_CM


def _partition(rng: np.random.Generator, length: int, lo: int, hi: int) -> list[int]:
    """Split ``length`` cm into grid-multiple parts within [lo, hi] where possible."""
    n, lo_n, hi_n = length // GRID_CM, math.ceil(lo / GRID_CM), hi // GRID_CM
    k_min, k_max = max(1, math.ceil(n / hi_n)), max(1, n // lo_n)
    k = int(rng.integers(k_min, max(k_min, k_max) + 1))
    parts, rem = [], n
    for i in range(k - 1):
        left = k - i - 1
        a, b = max(lo_n, rem - left * hi_n), min(hi_n, rem - left * lo_n)
        if a > b:
            a = b = rem // (k - i)
        w = int(rng.integers(a, b + 1))
        parts.append(w)
        rem -= w
    parts.append(rem)
    return [w * GRID_CM for w in parts]


def _band(
    rng: np.random.Generator,
    x0: int,
    x1: int,
    special: list[tuple[str, int, int]],
    lo: int,
    hi: int,
) -> list[tuple[int, int, str]]:
    """Rooms (x0, x1, label) along [x0, x1]: the special (label, min, max) slots that fit, the rest
    split in [lo, hi] and labelled "" (to be named by the caller)."""
    length = x1 - x0
    slots: list[tuple[int, str]] = []
    for label, a, b in special:
        room = length - sum(w for w, _ in slots) - lo  # leave at least one ordinary room
        if room >= a:
            slots.append((uniform_snap(rng, a, min(b, room)), label))
    rest = length - sum(w for w, _ in slots)
    widths = [(w, "") for w in _partition(rng, rest, lo, hi)]
    for slot in slots:
        widths.insert(int(rng.integers(len(widths) + 1)), slot)
    out, x = [], x0
    for w, label in widths:
        out.append((x, x + w, label))
        x += w
    return out


def random_layout(rng: np.random.Generator, kind: str, gross: float) -> Layout | None:
    if kind == "office":
        return _office(rng, gross)
    return _apartment_hall(rng, gross) if rng.random() < 0.65 else _apartment_bsp(rng, gross)


def _depths(rng: np.random.Generator, total: float, lo: int, hi: int) -> tuple[int, int]:
    total = snap(float(np.clip(total, 2 * lo, 2 * hi)))
    a = uniform_snap(rng, max(lo, total - hi), min(hi, total - lo))
    return a, total - a


def _corridor_plan(
    rng: np.random.Generator,
    gross: float,
    corridor: tuple[int, int],
    aspect: tuple[float, float],
    depth: tuple[int, int],
) -> tuple[int, int, int, int]:
    """A corridor along x between two bands of rooms, for an interior of ``gross`` cm²: the
    corridor's width (drawn in ``corridor``), the depth of the band below it, and the interior's
    height and width (cm). The bands' depths are drawn in ``depth`` so that with the corridor
    they make the height that an aspect ratio drawn in ``aspect`` asks for."""
    cw = uniform_snap(rng, *corridor)
    ratio = rng.uniform(*aspect)
    da, db = _depths(rng, math.sqrt(gross / ratio) - cw, *depth)
    h = da + cw + db
    return cw, da, h, snap(gross / h)


def _apartment_hall(rng: np.random.Generator, gross: float) -> Layout | None:
    hw, da, h, w = _corridor_plan(rng, gross, (140, 170), (1.1, 1.8), (270, 480))
    lw = uniform_snap(rng, 320, 560)
    lw = min(lw, w - 250)
    if lw < 300:
        return None
    tiles: list[tuple[int, int, int, int]] = []
    labels: list[str] = []

    def add(box: tuple[int, int, int, int], label: str) -> int:
        tiles.append(box)
        labels.append(label)
        return len(tiles) - 1

    open_pairs: set[tuple[int, int]] = set()
    # Living zone at x in [0, lw], full depth; optionally a kitchen on one band's side.
    kitchen = None
    if h >= 800 and rng.random() < 0.6:
        if rng.random() < 0.5:
            kitchen = add((0, 0, lw, da), KITCHEN)
            living = add((0, da, lw, h), LIVING)
        else:
            living = add((0, 0, lw, da + hw), LIVING)
            kitchen = add((0, da + hw, lw, h), KITCHEN)
        if rng.random() < 0.5:
            open_pairs.add((min(kitchen, living), max(kitchen, living)))
    else:
        living = add((0, 0, lw, h), LIVING)
    # Optional full-depth room closing the hall.
    x_end = w
    if w - lw >= 300 + 250 + 250 and rng.random() < 0.35:
        e = uniform_snap(rng, 300, min(450, w - lw - 250))
        x_end = w - e
        add((x_end, 0, w, h), "Bedroom")
    hall = add((lw, da, x_end, da + hw), CORRIDOR)
    if rng.random() < 0.6:
        open_pairs.add((min(hall, living), max(hall, living)))
    bath_band = int(rng.integers(2))
    band_rooms = []
    for band, (y0, y1) in enumerate(((0, da), (da + hw, h))):
        special = [(BATH, 170, 240)] if band == bath_band else []
        if band != bath_band and kitchen is None:
            special.append((KITCHEN, 250, 380))
        for x0, x1, label in _band(rng, lw, x_end, special, 250, 480):
            band_rooms.append(add((x0, y0, x1, y1), label))
    # Name the unnamed band rooms: a bathroom first, then a kitchen next to the living zone if
    # rooms are left for bedrooms (in a small flat the kitchen is part of the living room).
    unnamed = [i for i in band_rooms if not labels[i]]
    if BATH not in labels and unnamed:
        bath = min(unnamed, key=lambda i: tile_area(tiles[i]))
        labels[bath] = BATH
        unnamed.remove(bath)
    near = [i for i in unnamed if tiles[i][0] == lw]
    if KITCHEN not in labels and near and len(unnamed) >= 2:
        labels[near[0]] = KITCHEN
    unnamed = [i for i in band_rooms if not labels[i]]
    for n, i in enumerate(unnamed):
        labels[i] = "Office" if n == 2 and len(unnamed) >= 4 else "Bedroom"
    return Layout(tiles, labels, hall, w, h, open_pairs)


def _apartment_bsp(rng: np.random.Generator, gross: float) -> Layout | None:
    aspect = rng.uniform(1.0, 1.6)
    h = snap(math.sqrt(gross / aspect))
    w = snap(gross / h)
    leaves: list[tuple[int, int, int, int]] = []
    stack = [(0, 0, w, h)]
    lines: tuple[list[int], list[int]] = ([], [])  # x of vertical cuts, y of horizontal cuts
    while stack:
        x0, y0, x1, y1 = stack.pop()
        sx, sy = x1 - x0, y1 - y0
        big = max(sx, sy)
        if big < 2 * 250 or (sx * sy <= rng.uniform(9e4, 2.2e5) and big <= 600):
            leaves.append((x0, y0, x1, y1))
            continue
        along_x = sx >= sy
        start = x0 if along_x else y0
        lo, hi = start + max(250, 0.3 * big), start + min(big - 250, 0.7 * big)
        cut = start + uniform_snap(rng, lo - start, hi - start)
        # Line up with a parallel wall nearby (offset walls 5–30 cm apart look like mistakes).
        near = [v for v in lines[not along_x] if 0 < abs(v - cut) < 30 and lo <= v <= hi]
        cut = near[0] if near else cut
        lines[not along_x].append(cut)
        if along_x:
            stack += [(x0, y0, cut, y1), (cut, y0, x1, y1)]
        else:
            stack += [(x0, y0, x1, cut), (x0, cut, x1, y1)]
    if len(leaves) < 3:
        return None
    order = sorted(range(len(leaves)), key=lambda i: tile_area(leaves[i]))
    bath = order[0]
    if tile_area(leaves[bath]) > 10e4:
        # No small room: carve a bathroom strip off the narrowest room that has space for it.
        roomy = [i for i in order[:-1] if max(_sides(leaves[i])) >= 170 + 250]
        if roomy:
            i = min(roomy, key=lambda i: min(_sides(leaves[i])))
            x0, y0, x1, y1 = leaves[i]
            strip = uniform_snap(rng, 170, 240)
            if x1 - x0 >= y1 - y0:
                leaves[i], extra = (x0 + strip, y0, x1, y1), (x0, y0, x0 + strip, y1)
            else:
                leaves[i], extra = (x0, y0 + strip, x1, y1), (x0, y0, x1, y0 + strip)
            leaves.append(extra)
            order = sorted(range(len(leaves)), key=lambda i: tile_area(leaves[i]))
            bath = len(leaves) - 1
    order.remove(bath)
    order.insert(0, bath)
    labels = ["Bedroom"] * len(leaves)
    labels[order[-1]] = LIVING
    labels[bath] = BATH
    if len(leaves) >= 4:  # else the kitchen is part of the living room
        labels[order[-2]] = KITCHEN
    if len(leaves) >= 6 and tile_area(leaves[order[1]]) <= 9e4:
        labels[order[1]] = BATH
    elif len(leaves) >= 6:
        labels[order[1]] = "Office"
    return Layout(leaves, labels, order[-1], w, h)


def _office(rng: np.random.Generator, gross: float) -> Layout | None:
    cw, da, h, w = _corridor_plan(rng, gross, (150, 220), (1.4, 2.6), (280, 560))
    if w < 300:
        return None
    tiles: list[tuple[int, int, int, int]] = []
    labels: list[str] = []
    x0, x1 = 0, w
    if w >= 1100 and rng.random() < 0.45:
        x0 = uniform_snap(rng, 400, 650)
        tiles.append((0, 0, x0, h))
        labels.append("Meeting_Room")
    if w - x0 >= 1100 and rng.random() < 0.25:
        x1 = w - uniform_snap(rng, 400, 650)
        tiles.append((x1, 0, w, h))
        labels.append("Meeting_Room" if x0 == 0 else "Office")
    hub = len(tiles)
    tiles.append((x0, da, x1, da + cw))
    labels.append(CORRIDOR)
    bath_band = int(rng.integers(2))
    band_rooms = []
    for band, (y0, y1) in enumerate(((0, da), (da + cw, h))):
        special = [(BATH, 180, 260)] if band == bath_band else [("Kitchen", 250, 350)]
        for a, b, label in _band(rng, x0, x1, special, 250, 500):
            tiles.append((a, y0, b, y1))
            labels.append(label)
            band_rooms.append(len(tiles) - 1)
    if "Meeting_Room" not in labels:
        wide = [i for i in band_rooms if not labels[i] and tiles[i][2] - tiles[i][0] >= 420]
        if wide:
            labels[wide[int(rng.integers(len(wide)))]] = "Meeting_Room"
    for i in band_rooms:
        labels[i] = labels[i] or "Office"
    return Layout(tiles, labels, hub, w, h)


def symmetry(layout: Layout, which: int) -> Layout:
    """One of the 8 symmetries of the rectangle: bit 0 mirrors x, bit 1 mirrors y, bit 2 swaps
    the axes."""
    w, h = layout.width, layout.height

    def move(box: tuple[int, int, int, int]) -> tuple[int, int, int, int]:
        x0, y0, x1, y1 = box
        if which & 1:
            x0, x1 = w - x1, w - x0
        if which & 2:
            y0, y1 = h - y1, h - y0
        return (y0, x0, y1, x1) if which & 4 else (x0, y0, x1, y1)

    return Layout(
        [move(t) for t in layout.tiles],
        layout.labels,
        layout.hub,
        h if which & 4 else w,
        w if which & 4 else h,
        layout.open_pairs,
        None if layout.cut is None else move(layout.cut),
    )


def tile_area(box: tuple[int, int, int, int]) -> int:
    return (box[2] - box[0]) * (box[3] - box[1])


def _sides(box: tuple[int, int, int, int]) -> tuple[int, int]:
    return box[2] - box[0], box[3] - box[1]


def cut_corner(layout: Layout, gross: float) -> Layout | None:
    """Remove one corner room (L-shaped footprint), the one leaving an interior closest to gross."""
    w, h = layout.width, layout.height
    spare = ("Bedroom", "Office", "Meeting_Room")  # one of these may go if another remains
    if sum(label in spare for label in layout.labels) < 2:
        return None
    best, best_err = None, math.inf
    for i, (x0, y0, x1, y1) in enumerate(layout.tiles):
        if i == layout.hub or layout.labels[i] not in spare:
            continue
        sides = (x0 == 0) + (x1 == w) + (y0 == 0) + (y1 == h)
        corner = (x0 == 0 or x1 == w) and (y0 == 0 or y1 == h)
        if sides != 2 or not corner or tile_area((x0, y0, x1, y1)) < 6e4:
            continue
        err = abs(w * h - tile_area(layout.tiles[i]) - gross)
        if err < best_err:
            best, best_err = i, err
    if best is None:
        return None
    index = [i for i in range(len(layout.tiles)) if i != best]
    new = {old: n for n, old in enumerate(index)}
    return Layout(
        [layout.tiles[i] for i in index],
        [layout.labels[i] for i in index],
        new[layout.hub],
        w,
        h,
        {(new[a], new[b]) for a, b in layout.open_pairs if best not in (a, b)},
        layout.tiles[best],
    )
