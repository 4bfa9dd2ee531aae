"""Navigation on the belief map: grid path planning and a pure-pursuit path follower.

Costs: a cell believed a wall is an obstacle, inflated by the robot's radius; unknown cells are
traversable at ``unknown_cost`` (× a free cell); cells near a wall cost extra so that paths keep
clear of walls. Shortest paths come from one Dijkstra search per replan from the robot to every
cell, so that one search ranks every candidate goal. Its edge costs are those of scikit-image's
:class:`skimage.graph.MCP_Geometric` (8-connected; a step costs the mean of its two cells' costs
times its length, 1 or √2) and it returns the same costs (the tests check it against MCP); it is a
compiled bucket-queue kernel because it runs at every replan and is about 5× faster than MCP here.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from numba import njit
from scipy import ndimage

from sfw_gym.core.angles import wrap_angle_compiled
from sfw_gym.core.exact_math import hypot as exact_hypot
from sfw_gym.mapping.grid import GridSpec, belief_classes

#: Defaults of :class:`WallBand`: the extra cost of a cell within the robot's radius of a wall,
#: and the width (m) of the band beyond the radius where that cost falls to 0.
INFLATION_COST, CLEARANCE_M = 8.0, 0.2


@dataclass(frozen=True)
class WallBand:
    """How walls raise the cost of the cells around them (:func:`traversal_costs`).

    Cells within ``radius_m`` of a wall cost ``inflation_cost`` more, falling linearly to 0 at
    ``radius_m + clearance_m``; cells within ``lethal_radius_m`` of a wall are obstacles
    (default: half a cell, i.e. only the wall cells themselves).
    """

    radius_m: float
    inflation_cost: float = INFLATION_COST
    clearance_m: float = CLEARANCE_M
    lethal_radius_m: float | None = None

    @property
    def outer_m(self) -> float:
        """Where the band ends: no extra cost this far from a wall or farther."""
        return self.radius_m + self.clearance_m

    def lethal_m(self, resolution_m: float) -> float:
        """The lethal radius on cells of ``resolution_m``."""
        return 0.5 * resolution_m if self.lethal_radius_m is None else self.lethal_radius_m


def traversal_costs(
    belief_u8: np.ndarray,
    resolution_m: float,
    radius_m: float,
    *,
    unknown_cost: float = 1.5,
    inflation_cost: float = INFLATION_COST,
    clearance_m: float = CLEARANCE_M,
    lethal_radius_m: float | None = None,
    blocked: np.ndarray | None = None,
    wall_distance: np.ndarray | None = None,
) -> np.ndarray:
    """Per-cell traversal cost of the belief map (``inf`` = obstacle).

    A free cell costs 1 and an unknown one ``unknown_cost``. Believed walls (and ``blocked``
    cells) are obstacles, inflated by ``lethal_radius_m``; cells within the robot's radius of a
    wall cost ``inflation_cost`` more, falling linearly to 0 at ``radius_m + clearance_m``. The
    map's walls are blurred estimates, so the default inflation is soft: a doorway narrower
    than the estimate stays passable, at a price.

    Args:
        belief_u8: The belief map, ``[row, col]``.
        resolution_m: Cell size, metres.
        radius_m: Robot radius, metres.
        unknown_cost: Cost of an unknown cell.
        inflation_cost: Extra cost of a cell within ``radius_m`` of a wall.
        clearance_m: Width of the falling cost band beyond the radius.
        lethal_radius_m: Cells within this of a wall are obstacles (default: half a cell, i.e.
            only the wall cells themselves).
        blocked: Optional extra obstacle mask (e.g. where the robot bumped).
        wall_distance: :func:`wall_distance_m` of the walls and ``blocked`` cells, if known
            (walls change more rarely than the rest of the belief: callers may cache it).

    Returns:
        float64 array of the belief's shape.
    """
    _, wall, unknown = belief_classes(belief_u8)
    if blocked is not None:
        wall = wall | blocked
    cost = np.where(unknown, float(unknown_cost), 1.0)
    if wall.any():
        dist = wall_distance_m(wall, resolution_m) if wall_distance is None else wall_distance
        band = WallBand(radius_m, inflation_cost, clearance_m, lethal_radius_m)
        cost += wall_cost_term(dist, resolution_m, band)
    return cost


def wall_cost_term(wall_distance: np.ndarray, resolution_m: float, band: WallBand) -> np.ndarray:
    """The part of :func:`traversal_costs` that depends on the walls alone (added to the cell's
    own cost): the inflation ``band``, and ``inf`` within its lethal radius."""
    outer = band.outer_m
    clearance = band.clearance_m
    term = band.inflation_cost * np.clip((outer - wall_distance) / clearance, 0.0, 1.0)
    term[wall_distance <= band.lethal_m(resolution_m)] = np.inf
    return term


def update_wall_cost_term(
    term: np.ndarray, walls: np.ndarray, changed: np.ndarray, resolution_m: float, band: WallBand
) -> None:
    """Bring ``term`` (:func:`wall_cost_term` of an earlier ``walls``) up to date in place, where
    the cells ``changed`` (flat indices) became or stopped being walls: only the cells within
    the band's reach of them are recomputed, with the same formula (the same values as a full
    recomputation)."""
    outer = band.outer_m
    lethal = band.lethal_m(resolution_m)
    reach, offsets, dist = _band_offsets(float(resolution_m), float(outer))
    clearance, inflation = band.clearance_m, band.inflation_cost
    _update_wall_term(
        term, walls, changed, offsets, dist, reach, outer, clearance, inflation, lethal
    )


@functools.lru_cache(maxsize=8)
def _band_offsets(resolution_m: float, outer_m: float) -> tuple[int, np.ndarray, np.ndarray]:
    """The cells nearer than ``outer_m`` to a cell, nearest first: their reach (cells), offsets
    ``(K, 2)`` and distances (m) (read-only)."""
    reach = int(np.ceil(outer_m / resolution_m)) + 1
    dr, dc = np.mgrid[-reach : reach + 1, -reach : reach + 1]
    dist = np.sqrt((dr * dr + dc * dc).astype(np.float64)).ravel() * resolution_m
    near = dist < outer_m
    order = np.argsort(dist[near], kind="stable")  # nearest first: the first wall found is it
    offsets = np.stack([dr.ravel()[near], dc.ravel()[near]], axis=1)[order]
    out = offsets, dist[near][order]
    for a in out:
        a.flags.writeable = False
    return reach, *out


@njit(cache=True)
def _update_wall_term(
    term, walls, changed, offsets, dist, reach, outer, clearance, inflation, lethal
):  # pragma: no cover (compiled)
    h, w = walls.shape
    stamp = np.zeros(h * w, np.bool_)
    for i in changed:
        r0 = i // w
        c0 = i - r0 * w
        for r in range(max(r0 - reach, 0), min(r0 + reach + 1, h)):
            for c in range(max(c0 - reach, 0), min(c0 + reach + 1, w)):
                if stamp[r * w + c]:
                    continue
                stamp[r * w + c] = True
                value = 0.0
                for k in range(len(offsets)):
                    rr = r + offsets[k, 0]
                    cc = c + offsets[k, 1]
                    if 0 <= rr < h and 0 <= cc < w and walls[rr, cc]:
                        d = dist[k]
                        value = inflation * min(max((outer - d) / clearance, 0.0), 1.0)
                        if d <= lethal:
                            value = np.inf
                        break
                term[r, c] = value


def wall_distance_m(walls: np.ndarray, resolution_m: float) -> np.ndarray:
    """Distance (m) from every cell to the nearest cell of ``walls``."""
    return ndimage.distance_transform_edt(~walls) * resolution_m


#: Path cost (m) of the first, bounded search of a replan: a choice it can prove is kept (the
#: frontier agent's ``search_radius_m``, the region steering's), else the whole map is searched.
SEARCH_RADIUS_M = 4.0

#: Cost of an obstacle cell next to the robot (:func:`free_start`): passable, at a price.
FREE_START_COST = 20.0


def free_start(cost: np.ndarray, start_rc: tuple[int, int], radius_cells: int = 1) -> np.ndarray:
    """A copy of ``cost`` with the cells around the robot made passable.

    The robot stands where it stands: an inflated obstacle (or a wall misplaced by the map) under
    it must not trap the planner. Cells within ``radius_cells`` get a finite, high cost.
    """
    out = cost.copy()
    r, c = start_rc
    h, w = out.shape
    sl = (
        slice(max(r - radius_cells, 0), r + radius_cells + 1),
        slice(max(c - radius_cells, 0), c + radius_cells + 1),
    )
    patch = out[sl]
    patch[~np.isfinite(patch)] = FREE_START_COST
    if 0 <= r < h and 0 <= c < w and not np.isfinite(out[r, c]):
        out[r, c] = FREE_START_COST
    return out


@dataclass
class CostField:
    """Cheapest paths from the robot's cell to every cell of the grid.

    Attributes:
        start_rc: The robot's cell.
        cumulative: Path cost to each cell, in metres × cell cost (``inf`` = unreachable).
        resolution_m: Cell size, metres.
        predecessor: Flat index of each cell's predecessor on its cheapest path (-1: none).
        max_cost_m: The search stopped beyond this cost (``inf``: it covered every cell): cells
            that cost more are ``inf`` here whether they are reachable or not.
    """

    start_rc: tuple[int, int]
    cumulative: np.ndarray
    resolution_m: float
    predecessor: np.ndarray
    max_cost_m: float = np.inf

    @property
    def complete(self) -> bool:
        """Whether every reachable cell has its cost (the search was not bounded)."""
        return not np.isfinite(self.max_cost_m)

    def reachable(self) -> np.ndarray:
        """Mask of cells with a finite path cost."""
        return np.isfinite(self.cumulative)

    def path(self, goal_rc: tuple[int, int]) -> np.ndarray:
        """``(N, 2)`` cells ``(row, col)`` from the start to ``goal_rc`` (empty if unreachable)."""
        if not np.isfinite(self.cumulative[goal_rc]):
            return np.zeros((0, 2), np.int64)
        w = self.cumulative.shape[1]
        flat = _trace_back(self.predecessor, int(goal_rc[0]) * w + int(goal_rc[1]))
        return np.stack(np.divmod(flat, w), axis=1)


def cost_field(
    cost: np.ndarray,
    start_rc: tuple[int, int],
    resolution_m: float,
    max_cost_m: float = np.inf,
) -> CostField:
    """Dijkstra from ``start_rc`` over ``cost`` (8-connected; ``inf`` cells are obstacles; every
    other cell costs at least 1, as :func:`traversal_costs` makes them). With a finite
    ``max_cost_m`` the search stops there: cheaper cells get their exact cost, the rest ``inf``."""
    h, w = cost.shape
    r, c = int(start_rc[0]), int(start_rc[1])
    r, c = min(max(r, 0), h - 1), min(max(c, 0), w - 1)
    cum = np.empty((h, w), np.float64)
    pred = np.empty(h * w, np.int64)
    limit = max_cost_m / resolution_m if np.isfinite(max_cost_m) else np.inf
    cost = np.ascontiguousarray(cost, np.float64)
    cheapest = _dijkstra_8(cost, r, c, cum, pred, limit, float(resolution_m))
    if cheapest < 1.0:
        raise ValueError(f"cell costs must be >= 1 (or inf), got {cheapest}")
    return CostField((r, c), cum, resolution_m, pred, float(max_cost_m))


@njit(cache=True)
def _dijkstra_8(cost, r0, c0, cum, pred, limit, scale):  # pragma: no cover (compiled)
    """Single-source Dijkstra on the 8-connected grid with MCP_Geometric's edge costs.

    Cells cost at least 1, so every edge does: a bucket queue of width 1 (Dial's algorithm)
    then settles nodes in a valid order (no node in a bucket can improve another in it), which
    gives Dijkstra's exact costs without a heap. Entries improved later stay in their bucket
    and are skipped when popped. Between equal-cost predecessors the one with the lower cost
    wins, as in a heap-ordered Dijkstra (scikit-image's MCP): the same paths, not only the same
    costs. The search stops at the first bucket beyond ``limit`` (cell units); cells not
    settled by then are set back to ``inf``. Costs come out multiplied by ``scale`` (the cell
    size: metres).

    A bounded search touches only the cells within ``limit + 2`` steps of the start (every step
    costs at least 1): only that window is scanned for the costs' range, and the clean-up visits
    only the cells it pushed, so its cost grows with the cells searched, not with the grid.
    """
    h, w = cost.shape
    cum[:] = np.inf
    pred[:] = -1
    done = np.zeros(h * w, np.bool_)
    diagonal = math.sqrt(2.0)
    reach = h + w if limit == np.inf else int(limit) + 3
    r_lo, r_hi = max(r0 - reach, 0), min(r0 + reach + 1, h)
    c_lo, c_hi = max(c0 - reach, 0), min(c0 + reach + 1, w)
    max_cost, min_cost = 1.0, np.inf
    for r in range(r_lo, r_hi):
        for c in range(c_lo, c_hi):
            if max_cost < cost[r, c] < np.inf:
                max_cost = cost[r, c]
            min_cost = min(min_cost, cost[r, c])
    if min_cost < 1.0:
        return min_cost  # refused by cost_field
    n_buckets = int(max_cost * diagonal) + 2  # > the longest edge: the ring never wraps onto itself
    n_cells = (r_hi - r_lo) * (c_hi - c_lo)
    head = np.full(n_buckets, -1, np.int64)  # per bucket, its newest entry
    node = np.empty(8 * n_cells + 1, np.int64)  # entries: the node and the bucket's next entry
    below = np.empty(8 * n_cells + 1, np.int64)
    settled = np.empty(n_cells, np.int64)
    node[0], below[0], head[0] = r0 * w + c0, -1, 0
    n_entries, n_settled, pending, bucket = 1, 0, 1, 0
    cum[r0, c0] = 0.0
    while pending > 0 and bucket <= limit:
        e = head[bucket % n_buckets]
        if e < 0:
            bucket += 1
            continue
        head[bucket % n_buckets] = below[e]
        pending -= 1
        i = node[e]
        if done[i]:
            continue
        done[i] = True
        settled[n_settled] = i
        n_settled += 1
        r = i // w
        c = i - r * w
        d = cum[r, c]
        here = cost[r, c]
        for dr in range(-1, 2):
            rr = r + dr
            if rr < 0 or rr >= h:
                continue
            for dc in range(-1, 2):
                cc = c + dc
                if (dr == 0 and dc == 0) or cc < 0 or cc >= w or not cost[rr, cc] < np.inf:
                    continue
                j = rr * w + cc
                step = 0.5 * (here + cost[rr, cc]) * (diagonal if dr != 0 and dc != 0 else 1.0)
                if done[j]:
                    continue
                if d + step == cum[rr, cc] and d < cum.flat[pred[j]]:
                    pred[j] = i  # a tie: keep the predecessor a heap would settle first
                    continue
                if d + step < cum[rr, cc]:
                    cum[rr, cc] = d + step
                    pred[j] = i
                    slot = int(d + step) % n_buckets
                    node[n_entries], below[n_entries], head[slot] = j, head[slot], n_entries
                    n_entries += 1
                    pending += 1
    flat = cum.reshape(h * w)
    for e in range(n_entries):  # every cell given a cost was pushed: unsettled ones go back
        k = node[e]
        if not done[k]:
            flat[k] = np.inf
            pred[k] = -1
    for e in range(n_settled):
        flat[settled[e]] *= scale
    return min_cost


@njit(cache=True)
def _trace_back(pred, goal):  # pragma: no cover (compiled)
    """The cells from the search's start to ``goal`` along the predecessors ``pred`` (-1 at
    the start); a chain longer than the grid (a cycle: a corrupted search) is an error, not a
    hang."""
    n = 1
    i = goal
    while pred[i] >= 0:
        i = pred[i]
        n += 1
        if n > len(pred):
            raise ValueError("the path's predecessor chain has a cycle")
    out = np.empty(n, np.int64)
    i = goal
    for k in range(n - 1, -1, -1):
        out[k] = i
        i = pred[i]
    return out


def simplify_path(path_xy: np.ndarray, spacing_m: float) -> np.ndarray:
    """Thin a polyline so that consecutive points lie ``spacing_m`` or more apart (ends kept)."""
    path_xy = np.ascontiguousarray(path_xy, np.float64)
    if len(path_xy) <= 2:
        return path_xy
    return path_xy[_spaced_points(path_xy, float(spacing_m))]


@njit(cache=True)
def _spaced_points(path, spacing):  # pragma: no cover (compiled)
    """Indices of the points of ``simplify_path``: each ``spacing`` or more from the last kept."""
    n = len(path)
    keep = np.empty(n, np.int64)
    keep[0], m = 0, 1
    for i in range(1, n - 1):
        last = keep[m - 1]
        if math.hypot(path[i, 0] - path[last, 0], path[i, 1] - path[last, 1]) >= spacing:
            keep[m] = i
            m += 1
    keep[m] = n - 1
    return keep[: m + 1]


def densify_path(path_xy: np.ndarray, spacing_m: float) -> np.ndarray:
    """Insert points along a polyline so that neighbours lie at most ``spacing_m`` apart."""
    path_xy = np.ascontiguousarray(path_xy, np.float64)
    if len(path_xy) < 2:
        return path_xy
    return _densified(path_xy, float(spacing_m))


@njit(cache=True)
def _densified(path, spacing):  # pragma: no cover (compiled)
    """Each leg of ``path`` cut into ``ceil(length / spacing)`` equal steps (at least one)."""
    n_legs = len(path) - 1
    steps = np.empty(n_legs, np.int64)
    for i in range(n_legs):
        length = np.hypot(path[i + 1, 0] - path[i, 0], path[i + 1, 1] - path[i, 1])
        steps[i] = max(1, int(np.ceil(length / spacing)))
    out = np.empty((steps.sum() + 1, 2))
    out[0] = path[0]
    k = 1
    for i in range(n_legs):
        dx, dy = path[i + 1, 0] - path[i, 0], path[i + 1, 1] - path[i, 1]
        for j in range(steps[i]):
            t = (j + 1) / steps[i]
            out[k, 0] = path[i, 0] + dx * t
            out[k, 1] = path[i, 1] + dy * t
            k += 1
    return out


def cells_to_world(grid: GridSpec, cells_rc: np.ndarray) -> np.ndarray:
    """World ``(x, y)`` of cell centres, ``(N, 2)``."""
    return grid.cell_to_world(np.asarray(cells_rc).reshape(-1, 2))


@dataclass
class PurePursuit:
    """Pure-pursuit follower of a polyline (Coulter 1992) for a differential-drive robot.

    The carrot is the first path point at least ``lookahead_m`` from the robot beyond the nearest
    point on the path; the turn rate follows the carrot's bearing. Large bearing errors turn the
    robot in place first.

    Attributes:
        lookahead_m: Carrot distance.
        turn_in_place_rad: Bearing error above which the robot turns without driving.
        angular_gain: Turn rate (fraction of the limit) per radian of bearing error.
        goal_tolerance_m: Distance at which the path's end counts as reached.
    """

    lookahead_m: float = 0.5
    turn_in_place_rad: float = 0.9
    angular_gain: float = 1.5
    goal_tolerance_m: float = 0.2

    def __post_init__(self) -> None:
        self.path = np.zeros((0, 2))
        self._progress = 0

    def set_path(self, path_xy: np.ndarray) -> None:
        """Follow a new ``(N, 2)`` world polyline (resampled every 5 cm)."""
        self.path = densify_path(np.asarray(path_xy, np.float64).reshape(-1, 2), 0.05)
        self._progress = 0

    @property
    def has_path(self) -> bool:
        """Whether a path is set and its end not yet reached."""
        return len(self.path) > 0

    def remaining_m(self, xy: np.ndarray) -> float:
        """Distance from ``xy`` along the rest of the path to its end."""
        if not self.has_path:
            return 0.0
        rest = self.path[self._progress :]
        legs = np.linalg.norm(np.diff(rest, axis=0), axis=1).sum() if len(rest) > 1 else 0.0
        return float(np.linalg.norm(rest[0] - xy) + legs)

    def command(self, pose: tuple[float, float, float]) -> tuple[float, float]:
        """``(linear, angular)`` fractions in [-1, 1] towards the carrot; (0, 0) at the end.

        The progress index advances to the nearest of the next 20 path points (never backwards);
        the carrot is the first point from there at ``lookahead_m`` or more (else the end)."""
        if not self.has_path:
            return 0.0, 0.0
        linear, angular, progress = _pursue(
            self.path,
            self._progress,
            float(pose[0]),
            float(pose[1]),
            float(pose[2]),
            self.lookahead_m,
            self.goal_tolerance_m,
            self.turn_in_place_rad,
            self.angular_gain,
        )
        if progress < 0:  # the end is reached
            self.path = np.zeros((0, 2))
        else:
            self._progress = progress
        return linear, angular


@njit(cache=True)
def _pursue(
    path, progress, x, y, heading, lookahead, tolerance, turn_in_place, gain
):  # pragma: no cover (compiled)
    """:meth:`PurePursuit.command` in one call: ``(linear, angular, progress)``, progress -1 at
    the end. Distances as the Python code measured them (CPython's ``math.hypot`` to the end,
    numpy's ``hypot`` along the path), so the commands are the same to the bit."""
    n = len(path)
    if exact_hypot(path[n - 1, 0] - x, path[n - 1, 1] - y) <= tolerance:
        return 0.0, 0.0, -1
    best, nearest = np.inf, progress
    for i in range(progress, min(progress + 20, n)):
        d = np.hypot(path[i, 0] - x, path[i, 1] - y)
        if d < best:
            best, nearest = d, i
    carrot = n - 1
    for i in range(nearest, n):
        if np.hypot(path[i, 0] - x, path[i, 1] - y) >= lookahead:
            carrot = i
            break
    bearing = wrap_angle_compiled(math.atan2(path[carrot, 1] - y, path[carrot, 0] - x) - heading)
    angular = min(max(gain * bearing, -1.0), 1.0)
    if abs(bearing) > turn_in_place:
        return 0.0, math.copysign(1.0, bearing), nearest
    return min(max(math.cos(bearing), 0.2), 1.0), angular, nearest


def to_discrete(linear: float, angular: float, deadband: float = 0.35) -> int:
    """Map a (linear, angular) command to the discrete actions 0 forward, 1 left, 2 right."""
    if abs(angular) > deadband or linear <= 0.0:
        return 1 if angular > 0 else 2
    return 0


def disk_offsets(radius_cells: float) -> np.ndarray:
    """``(K, 2)`` integer offsets ``(dr, dc)`` with ``dr² + dc² ≤ radius_cells²``."""
    k = int(np.floor(radius_cells))
    dr, dc = np.mgrid[-k : k + 1, -k : k + 1]
    keep = dr**2 + dc**2 <= radius_cells**2 + 1e-9
    return np.stack([dr[keep], dc[keep]], axis=1)


def disk_cells(shape: tuple[int, int], cell: tuple[int, int], radius_cells: float):
    """``(rows, cols)`` of the cells within ``radius_cells`` of ``cell`` (clipped to ``shape``),
    in raster order."""
    dr, dc = _disk(float(radius_cells))
    rr, cc = dr + int(cell[0]), dc + int(cell[1])
    inside = (rr >= 0) & (rr < shape[0]) & (cc >= 0) & (cc < shape[1])
    return rr[inside], cc[inside]


@functools.lru_cache(maxsize=32)
def _disk(radius_cells: float) -> tuple[np.ndarray, np.ndarray]:
    """Row and column offsets of a disk of ``radius_cells``, raster order (read-only)."""
    k = int(np.ceil(radius_cells))
    dr, dc = np.mgrid[-k : k + 1, -k : k + 1]
    keep = dr**2 + dc**2 <= radius_cells * radius_cells
    out = dr[keep], dc[keep]
    for a in out:
        a.flags.writeable = False
    return out


def mark_disk(mask: np.ndarray, cell: tuple[int, int], radius_cells: float) -> None:
    """Set the cells of ``mask`` within ``radius_cells`` of ``cell`` (in place, clipped)."""
    mask[disk_cells(mask.shape, cell, radius_cells)] = True


def mark_contact(
    mask: np.ndarray, grid: GridSpec, pose: tuple[float, float, float], radius_m: float
) -> None:
    """Mark where a bumper fired, just ahead of the robot, as an obstacle (a 1-cell disk; the
    mapper marks one cell, walls are longer)."""
    x, y, theta = pose
    reach = radius_m + 0.5 * grid.resolution_m
    contact = np.array([x + reach * np.cos(theta), y + reach * np.sin(theta)])
    mark_disk(mask, tuple(grid.world_to_cell(contact)), 1.0)


@njit(cache=True)
def min_over_offsets(values, cells, offsets):  # pragma: no cover (compiled)
    """Per cell ``(N, 2)``: the minimum of ``values`` over ``cell + offsets`` inside the grid,
    and the index of the first offset that attains it (0 where none is finite)."""
    h, w = values.shape
    out = np.full(len(cells), np.inf)
    arg = np.zeros(len(cells), np.int64)
    for i in range(len(cells)):
        for k in range(len(offsets)):
            r = cells[i, 0] + offsets[k, 0]
            c = cells[i, 1] + offsets[k, 1]
            if 0 <= r < h and 0 <= c < w and values[r, c] < out[i]:
                out[i] = values[r, c]
                arg[i] = k
    return out, arg
