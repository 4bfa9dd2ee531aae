"""Physically valid paths through a floorplan's free space: a surveyor's lawnmower and a walk.

Both keep ``clearance_m`` from every wall and never jump: consecutive points are ``step_m`` apart
along collision-free straight pieces (transits between them are found by breadth-first search on a
5 cm grid and string-pulled), so a mapper never joins two samples through a wall.

- :func:`survey`: a wall-following pass around every boundary, then a boustrophedon of passes
  ``spacing_m`` apart (the dense survey of the mapper benchmarks).
- :func:`walk`: a person walking through the building: random places spread over the free space
  (one per ``area_per_stop_m2``), visited nearest-first, as a phone-carrying surveyor would.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import shapely
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import breadth_first_order
from shapely.geometry import LineString

from sfw_gym.core.errors import ConfigError
from sfw_gym.world.floorplan import Floorplan

#: The robot's radius plus 2 cm: how far the default paths keep from the walls.
CLEARANCE_M = 0.19
PLAN_RES_M = 0.05  # grid of the transit planner


class TransitPlanner:
    """Collision-free transits inside a region: straight if possible, else a path found by
    breadth-first search on a grid (8-neighbours) and shortened by string pulling."""

    def __init__(self, region) -> None:
        self.region = region
        xmin, ymin, xmax, ymax = region.bounds
        self.origin = np.array([xmin - PLAN_RES_M, ymin - PLAN_RES_M])
        nx = math.ceil((xmax - xmin) / PLAN_RES_M) + 3
        ny = math.ceil((ymax - ymin) / PLAN_RES_M) + 3
        gx, gy = np.meshgrid(
            self.origin[0] + (np.arange(nx) + 0.5) * PLAN_RES_M,
            self.origin[1] + (np.arange(ny) + 0.5) * PLAN_RES_M,
        )
        self.centres = np.stack([gx.ravel(), gy.ravel()], axis=1)
        ok = shapely.contains_xy(region, gx, gy)
        self.ok = ok
        node = np.full(ok.size, -1, np.int64)
        node[ok.ravel()] = np.arange(ok.sum())
        self.node = node.reshape(ok.shape)
        self.cell_of = np.flatnonzero(ok.ravel())
        src, dst, w = [], [], []
        for dr, dc in ((0, 1), (1, 0), (1, 1), (1, -1)):
            a = ok[: ny - dr, max(0, -dc) : nx - max(0, dc)]
            b = ok[dr:, max(0, dc) : nx - max(0, -dc)]
            both = a & b
            src.append(self.node[: ny - dr, max(0, -dc) : nx - max(0, dc)][both])
            dst.append(self.node[dr:, max(0, dc) : nx - max(0, -dc)][both])
            w.append(np.full(int(both.sum()), math.hypot(dr, dc)))
        s, d, ww = np.concatenate(src), np.concatenate(dst), np.concatenate(w)
        n = int(ok.sum())
        self.graph = coo_matrix((np.r_[ww, ww], (np.r_[s, d], np.r_[d, s])), shape=(n, n)).tocsr()

    def _nearest_node(self, p) -> int:
        i = int((p[1] - self.origin[1]) / PLAN_RES_M)
        j = int((p[0] - self.origin[0]) / PLAN_RES_M)
        best, best_d = -1, math.inf
        for a in range(max(i - 3, 0), min(i + 4, self.ok.shape[0])):
            for b in range(max(j - 3, 0), min(j + 4, self.ok.shape[1])):
                if self.ok[a, b]:
                    d = math.dist(self.centres[a * self.ok.shape[1] + b], p)
                    if d < best_d:
                        best, best_d = int(self.node[a, b]), d
        return best

    def path(self, a, b) -> list:
        """Waypoints strictly between ``a`` and ``b``."""
        if self.region.contains(LineString([a, b])):
            return []
        s, t = self._nearest_node(a), self._nearest_node(b)
        _, pred = breadth_first_order(self.graph, s, directed=False)
        chain = [t]
        while chain[-1] != s and chain[-1] >= 0:
            chain.append(int(pred[chain[-1]]))
        pts = [np.asarray(a)] + [self.centres[self.cell_of[v]] for v in chain[::-1]]
        pts.append(np.asarray(b))
        out, i = [], 0  # string pulling: keep only the corners the region forces
        while i < len(pts) - 1:
            j = len(pts) - 1
            while j > i + 1 and not self.region.contains(LineString([pts[i], pts[j]])):
                j -= 1
            out.append(tuple(pts[j]))
            i = j
        return out[:-1]


def resample(waypoints: list, step_m: float) -> np.ndarray:
    """Points every ``step_m`` along a polyline (its vertices kept)."""
    out = []
    for a, b in itertools.pairwise(waypoints):
        a, b = np.asarray(a, float), np.asarray(b, float)
        n = max(1, math.ceil(math.dist(a, b) / step_m))
        out.append(a + (np.arange(n)[:, None] / n) * (b - a))
    out.append(np.asarray(waypoints[-1], float)[None])
    return np.concatenate(out)


def survey(
    plan: Floorplan,
    spacing_m: float,
    wall_follow: bool = True,
    *,
    step_m: float = 0.05,
    clearance_m: float = CLEARANCE_M,
) -> np.ndarray:
    """The continuous survey path ``(N, 2)`` (metres) described in the module docstring."""
    region = _region(plan, clearance_m)
    planner = TransitPlanner(region)
    route: list = []

    def go(seq: list) -> None:
        if route:
            route.extend(planner.path(route[-1], seq[0]))
        route.extend(seq)

    if wall_follow:
        for ring in (region.exterior, *region.interiors):
            loop = list(ring.coords)[:-1]
            if route:  # enter the loop at its point nearest the robot
                i = int(np.argmin(np.linalg.norm(np.asarray(loop) - route[-1], axis=1)))
                loop = loop[i:] + loop[:i]
            go([*loop, loop[0]])
    xmin, ymin, xmax, ymax = region.bounds
    segs, rows = [], []
    for row, y in enumerate(np.arange(ymin + spacing_m / 2, ymax, spacing_m)):
        cut = region.intersection(LineString([(xmin - 1, y), (xmax + 1, y)]))
        for g in getattr(cut, "geoms", [cut]):
            if g.geom_type == "LineString" and g.length > 0:
                (x0, _), (x1, _) = g.coords[0], g.coords[-1]
                segs.append(((min(x0, x1), y), (max(x0, x1), y)))
                rows.append(row)
    left = set(range(len(segs)))
    last = None
    while left:
        here = route[-1] if route else segs[0][0]
        gap = {i: min(math.dist(here, segs[i][0]), math.dist(here, segs[i][1])) for i in left}
        nxt = None
        if last is not None:  # boustrophedon: an overlapping segment of the next or previous row
            lo, hi = segs[last][0][0], segs[last][1][0]
            cands = [
                i
                for i in left
                if abs(rows[i] - rows[last]) == 1
                and min(hi, segs[i][1][0]) > max(lo, segs[i][0][0])
            ]
            nxt = min(cands, key=gap.__getitem__) if cands else None
        if nxt is None:
            nxt = min(left, key=gap.__getitem__)
        left.remove(nxt)
        a, b = segs[nxt]
        go([a, b] if math.dist(here, a) <= math.dist(here, b) else [b, a])
        last = nxt
    return resample(route, step_m)


def walk(
    plan: Floorplan,
    rng: np.random.Generator,
    *,
    step_m: float = 0.1,
    area_per_stop_m2: float = 1.0,
    clearance_m: float = CLEARANCE_M,
) -> np.ndarray:
    """A walk through the building, ``(N, 2)`` metres, a point every ``step_m``.

    Stops are drawn uniformly in the free space (shrunk by ``clearance_m``; its largest part,
    where a narrow doorway splits it), one per ``area_per_stop_m2`` (at least 2); the walk starts
    at the first and always goes on to the nearest stop not yet visited, along collision-free
    transits.
    """
    if not (step_m > 0 and area_per_stop_m2 > 0):
        raise ConfigError(
            f"step_m and area_per_stop_m2 must be > 0, got {step_m!r}, {area_per_stop_m2!r}"
        )
    region = _region(plan, clearance_m)
    n_stops = max(2, round(region.area / area_per_stop_m2))
    xmin, ymin, xmax, ymax = region.bounds
    stops: list[np.ndarray] = []
    while len(stops) < n_stops:
        p = rng.uniform((xmin, ymin), (xmax, ymax), (4 * n_stops, 2))
        stops.extend(p[shapely.contains_xy(region, p[:, 0], p[:, 1])])
    left = list(stops[:n_stops])
    planner = TransitPlanner(region)
    route = [tuple(left.pop(0))]
    while left:
        here = np.asarray(route[-1])
        nxt = left.pop(int(np.argmin([math.dist(here, s) for s in left])))
        route.extend(planner.path(route[-1], tuple(nxt)))
        route.append(tuple(nxt))
    return resample(route, step_m)


def _region(plan: Floorplan, clearance_m: float):
    """Where a path's points may lie: the free space shrunk by ``clearance_m``, its largest part
    where a doorway narrower than two clearances splits it (no path may jump between parts)."""
    region = plan.free_space.buffer(-clearance_m)
    if region.is_empty:
        raise ConfigError(
            f"floorplan {plan.name!r}: no free space is {clearance_m} m from every wall"
        )
    return max(getattr(region, "geoms", [region]), key=lambda part: part.area)
