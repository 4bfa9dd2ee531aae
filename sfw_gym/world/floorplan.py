"""Floorplans: free space, walls with materials, wall counting, rasterisation, file formats."""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import shapely
from shapely.geometry import Polygon
from shapely.validation import explain_validity

from sfw_gym.core.atomic import write_text_atomic
from sfw_gym.core.constants import BULK_VERTICES, U8_FREE, U8_UNKNOWN, U8_WALL
from sfw_gym.core.errors import FloorplanError
from sfw_gym.world.ros_map import ROS_MAP_SUFFIXES, ros_map_free_space
from sfw_gym.world.wall_crossing import DEFAULT_MIN_PIECE_M, cross_walls, cross_walls_parallel

#: Wall materials that a floorplan may name; a radio preset maps each to a loss in dB.
MATERIALS = ("generic", "drywall", "wood", "glass", "brick", "concrete")
#: Thickness given to the exterior walls of plans that store only the free space (HouseExpo).
EXTERIOR_WALL_M = 0.1
#: Plausible extent of a building, metres: a plan outside this range is rejected.
MIN_EXTENT_M, MAX_EXTENT_M = 1.0, 500.0
#: A free space smaller than this cannot hold a robot: rejected as absurd.
MIN_AREA_M2 = 0.5
#: A free space with more vertices than this is refused (HouseExpo's have tens to hundreds; a
#: reset costs about 25 ms per 1,000 vertices: scripts/benchmarks/bench_plan_size.py).
MAX_VERTICES = 50_000
#: A floorplan file larger than this is refused before it is read (HouseExpo's are ~10 kB).
MAX_FILE_BYTES = 50_000_000
#: Above this many segments, wall counting runs on all cores.
_PARALLEL_MIN_SEGMENTS = 2048
FORMAT_NAME = "sfw_gym.floorplan"
FORMAT_VERSION = 1
#: The files a folder of plans holds: JSON plans (sfw_gym, HouseExpo) and ROS map YAMLs.
PLAN_SUFFIXES = (".json", *ROS_MAP_SUFFIXES)


@dataclass(frozen=True)
class Room:
    """A labelled axis-aligned room box (metres): metadata for placing routers and reporting."""

    label: str
    box: tuple[float, float, float, float]  # xmin, ymin, xmax, ymax


@dataclass(frozen=True, eq=False)
class Floorplan:
    """Ground-truth geometry of one building storey.

    The free space is one polygon (holes allowed); everything else inside the ``footprint`` is wall,
    and everything outside the footprint is outside the building. Each edge of the free space is the
    face of a wall and carries that wall's material.

    Attributes:
        free_space: shapely Polygon of the free space, metres.
        footprint: shapely Polygon of the building including its walls.
        edge_materials: material name of each free-space edge, in ring order (exterior ring, then
            holes; each ring without its closing vertex).
        name: an identifier (file id or generator seed).
        rooms: labelled room boxes (metadata).
        routers: the routers' positions ``((x, y), ...)``, metres, each in the free space; empty:
            none stored (the env places its own). The evaluation's order: ``--routers``, then
            these, then the env's k-means placement.
    """

    free_space: Polygon
    footprint: Polygon
    edge_materials: tuple[str, ...]
    name: str = "floorplan"
    rooms: tuple[Room, ...] = ()
    routers: tuple[tuple[float, float], ...] = ()
    edges: np.ndarray = field(init=False, repr=False)
    edge_material_index: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        _check_polygon(self.free_space, "free_space", self.name)
        _check_polygon(self.footprint, "footprint", self.name)
        if not self.footprint.buffer(1e-6).contains(self.free_space):
            raise FloorplanError(
                f"floorplan {self.name!r}: the footprint does not contain the free space"
            )
        edges = _polygon_edges(self.free_space)
        if len(self.edge_materials) != len(edges):
            raise FloorplanError(
                f"floorplan {self.name!r}: {len(self.edge_materials)} edge materials for "
                f"{len(edges)} free-space edges"
            )
        unknown = sorted(set(self.edge_materials) - set(MATERIALS))
        if unknown:
            raise FloorplanError(
                f"floorplan {self.name!r}: unknown wall material(s) {unknown}; "
                f"known: {list(MATERIALS)}"
            )
        index = np.array([MATERIALS.index(m) for m in self.edge_materials], dtype=np.int64)
        routers = tuple((float(x), float(y)) for x, y in self.routers)
        for i, (x, y) in enumerate(routers):
            if not (math.isfinite(x) and math.isfinite(y) and self.is_free(np.array([x, y]))):
                raise FloorplanError(
                    f"floorplan {self.name!r}: router {i} at ({x:g}, {y:g}) is not in the free "
                    "space"
                )
        object.__setattr__(self, "routers", routers)
        edges.setflags(write=False)
        index.setflags(write=False)
        object.__setattr__(self, "edges", edges)
        object.__setattr__(self, "edge_material_index", index)

    # ----------------------------------------------------------------------------------- geometry
    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax) of the footprint, metres."""
        return tuple(float(v) for v in self.footprint.bounds)  # type: ignore[return-value]

    @property
    def area_m2(self) -> float:
        """Free-space area in m²."""
        return float(self.free_space.area)

    def is_free(self, points: np.ndarray) -> np.ndarray:
        """Whether each point (…, 2) lies in the free space (boundary counts as not free)."""
        pts = np.asarray(points, dtype=np.float64)
        return shapely.contains_xy(self.free_space, pts[..., 0], pts[..., 1])

    def count_walls(
        self, a: np.ndarray, b: np.ndarray, *, min_piece_m: float = DEFAULT_MIN_PIECE_M
    ) -> np.ndarray:
        """Number of distinct walls crossed by each segment a[i]→b[i].

        A wall is a maximal piece of the segment outside the free space: a 0.1 m notch is one wall,
        a 1 cm bevel or staircase adds none, touching a wall's end is not a crossing.

        Args:
            a: (M, 2) or (2,) segment starts, metres.
            b: (M, 2) or (2,) segment ends, broadcast against ``a``.
            min_piece_m: pieces outside (and gaps inside a wall) shorter than this are ignored.

        Returns:
            (M,) int32 array (a scalar-shaped (1,) array for single points).
        """
        counts, _ = self._cross(a, b, np.zeros(len(MATERIALS)), min_piece_m)
        return counts

    def wall_loss_db(
        self,
        a: np.ndarray,
        b: np.ndarray,
        loss_by_material_db: Mapping[str, float] | float,
        *,
        min_piece_m: float = DEFAULT_MIN_PIECE_M,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Wall counts and summed wall losses (dB) for segments a[i]→b[i].

        Each crossed wall costs the loss of the material of the face the segment enters it by
        (one number: the same loss for every material).
        """
        if isinstance(loss_by_material_db, Mapping):
            table = np.array([float(loss_by_material_db[m]) for m in MATERIALS])
        else:
            table = np.full(len(MATERIALS), float(loss_by_material_db))
        return self._cross(a, b, table, min_piece_m)

    def _cross(
        self, a: np.ndarray, b: np.ndarray, table: np.ndarray, min_piece_m: float
    ) -> tuple[np.ndarray, np.ndarray]:
        a2, b2 = np.broadcast_arrays(np.asarray(a, np.float64), np.asarray(b, np.float64))
        if a2.shape[-1] != 2:
            raise FloorplanError(f"segment endpoints must have shape (M, 2), got {a2.shape}")
        a2 = np.array(a2.reshape(-1, 2), order="C")  # copies: broadcast views are read-only
        b2 = np.array(b2.reshape(-1, 2), order="C")
        if not (np.isfinite(a2).all() and np.isfinite(b2).all()):  # (NaN used to count 0 walls)
            bad = np.flatnonzero(~(np.isfinite(a2).all(1) & np.isfinite(b2).all(1)))
            raise FloorplanError(
                f"segment endpoints must be finite; rows {bad[:5].tolist()} are not"
            )
        edge_loss = table[self.edge_material_index]
        kernel = cross_walls_parallel if len(a2) >= _PARALLEL_MIN_SEGMENTS else cross_walls
        return kernel(self.edges, edge_loss, a2, b2, float(min_piece_m))

    def rasterize(self, resolution_m: float) -> tuple[np.ndarray, tuple[float, float]]:
        """Ground-truth grid covering ``bounds``: 0 wall, 255 free, 127 outside the building.

        Indexed [row, col] = [y, x]; cell centres at ``origin + (index + 0.5) * resolution_m``.
        Each cell is sampled at sub-cells no coarser than 5 cm; a cell with any wall sample is wall
        (so thin walls never vanish at coarse resolutions), else free with any free sample.

        Returns:
            (grid uint8 of shape (rows, cols), origin_xy).
        """
        if not (math.isfinite(resolution_m) and resolution_m > 0):
            raise FloorplanError(f"resolution_m must be a positive number, got {resolution_m!r}")
        xmin, ymin, xmax, ymax = self.bounds
        cols = max(1, math.ceil((xmax - xmin) / resolution_m - 1e-9))
        rows = max(1, math.ceil((ymax - ymin) / resolution_m - 1e-9))
        sub = max(1, math.ceil(resolution_m / 0.05 - 1e-9))
        step = resolution_m / sub
        xs = xmin + (np.arange(cols * sub) + 0.5) * step
        ys = ymin + (np.arange(rows * sub) + 0.5) * step
        gx, gy = np.meshgrid(xs, ys)
        free = shapely.contains_xy(self.free_space, gx, gy)
        inside = shapely.contains_xy(self.footprint, gx, gy)
        wall = inside & ~free
        free = free.reshape(rows, sub, cols, sub).any(axis=(1, 3))
        wall = wall.reshape(rows, sub, cols, sub).any(axis=(1, 3))
        grid = np.full((rows, cols), U8_UNKNOWN, dtype=np.uint8)
        grid[free] = U8_FREE
        grid[wall] = U8_WALL
        return grid, (xmin, ymin)

    # ----------------------------------------------------------------------------------- files
    def to_dict(self) -> dict[str, Any]:
        """The sfw_gym JSON representation (exact: coordinates are stored as floats)."""
        return {
            "format": FORMAT_NAME,
            "version": FORMAT_VERSION,
            "name": self.name,
            "free_space": {
                "exterior": _ring_coords(self.free_space.exterior),
                "holes": [_ring_coords(r) for r in self.free_space.interiors],
            },
            "footprint": _ring_coords(self.footprint.exterior),
            "edge_materials": list(self.edge_materials),
            "rooms": [{"label": r.label, "box": list(r.box)} for r in self.rooms],
        } | ({"routers": [list(r) for r in self.routers]} if self.routers else {})

    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write the plan as sfw_gym JSON, atomically (temp file + rename). Returns the path."""
        return write_text_atomic(Path(path), json.dumps(self.to_dict()))


def load_floorplan(source: str | os.PathLike[str] | Mapping[str, Any]) -> Floorplan:
    """Load a HouseExpo JSON file, an sfw_gym JSON file (or an already parsed dict) or a ROS
    map_server map (a ``.yaml`` / ``.yml`` path: :mod:`sfw_gym.world.ros_map`).

    Raises:
        FloorplanError: naming the file and the problem (not JSON, missing keys, too few vertices,
            NaN/inf, self-intersecting or zero-area outline, absurd size, …).
    """
    if isinstance(source, Mapping):
        where, data = "<dict>", source
    else:
        where = str(source) if str(source).isprintable() else repr(str(source))
        if Path(source).suffix.lower() in ROS_MAP_SUFFIXES:
            free_space = ros_map_free_space(source, MAX_FILE_BYTES)
            try:
                return floorplan_from_polygon(free_space, name=Path(source).stem)
            except FloorplanError as exc:
                raise FloorplanError(f"{where}: {exc}") from None
        try:
            size = Path(source).stat().st_size
            if size > MAX_FILE_BYTES:
                raise FloorplanError(
                    f"{where}: {size:,} bytes, over the {MAX_FILE_BYTES:,} a floorplan may have"
                )
            text = Path(source).read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError, ValueError) as exc:  # ValueError: a NUL in the name
            raise FloorplanError(f"{where}: cannot read floorplan file: {exc}") from None
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise FloorplanError(f"{where}: not valid JSON: {exc}") from exc
        except RecursionError:
            raise FloorplanError(f"{where}: not valid JSON: nested too deeply") from None
        except ValueError as exc:  # e.g. an integer of more than 4,300 digits
            raise FloorplanError(f"{where}: not valid JSON: {exc}") from None
    if not isinstance(data, Mapping):
        raise FloorplanError(f"{where}: expected a JSON object, got {type(data).__name__}")
    try:
        if data.get("format") == FORMAT_NAME:
            return _from_sfw_dict(data)
        if "verts" in data:
            return _from_houseexpo_dict(data)
    except FloorplanError as exc:
        raise FloorplanError(f"{where}: {exc}") from None
    except (TypeError, ValueError, OverflowError, RecursionError) as exc:  # values of odd types
        raise FloorplanError(f"{where}: malformed plan: {type(exc).__name__}: {exc}") from None
    raise FloorplanError(
        f"{where}: neither a HouseExpo plan (key 'verts') nor an sfw_gym plan "
        f"(key 'format' = {FORMAT_NAME!r}); keys found: {sorted(map(str, data))[:10]}"
    )


def floorplan_from_polygon(
    free_space: Polygon,
    *,
    name: str = "floorplan",
    material: str = "generic",
    exterior_wall_m: float = EXTERIOR_WALL_M,
    rooms: Sequence[Room] = (),
) -> Floorplan:
    """A plan whose walls all share one material, its footprint the free space grown by a wall.

    An outline of more than :data:`~sfw_gym.core.constants.BULK_VERTICES` vertices is simplified
    to 1 cm (far below the map's cells) first, and its footprint is grown from a 10 cm
    simplification by the wall plus their distance (an exterior wall thicker by up to about
    0.25 m in places): GEOS's buffer of a serrated 10,000-vertex outline takes seconds."""
    _check_polygon(free_space, "free_space", name)
    outline = free_space
    if _n_vertices(free_space) > BULK_VERTICES:
        free_space = free_space.simplify(0.01, preserve_topology=True)
        _check_polygon(free_space, "free_space (simplified to 1 cm)", name)
        coarse = free_space.simplify(0.1, preserve_topology=True)
        # grown by its distance from the outline more, the footprint holds the free space and
        # a wall of at least exterior_wall_m all round
        margin = coarse.hausdorff_distance(outline) + 0.001
        outline, exterior_wall_m = coarse, exterior_wall_m + margin
    with np.errstate(divide="ignore", invalid="ignore"):  # GEOS on slivers; validated below
        grown = outline.buffer(exterior_wall_m, join_style="mitre")
    footprint = Polygon(grown.exterior)
    n_edges = len(_polygon_edges(free_space))
    return Floorplan(free_space, footprint, (material,) * n_edges, name=name, rooms=tuple(rooms))


# --------------------------------------------------------------------------------------- helpers
def _from_houseexpo_dict(data: Mapping[str, Any]) -> Floorplan:
    name = str(data.get("id", "houseexpo"))
    ring = _parse_ring(data["verts"], "verts")
    rooms = []
    categories = data.get("room_category", {})
    if isinstance(categories, Mapping):
        for label, boxes in categories.items():
            for box in boxes if isinstance(boxes, list) else []:
                coords = _parse_numbers(box, f"room_category[{label!r}]", 4)
                rooms.append(Room(str(label), tuple(coords)))  # type: ignore[arg-type]
    return floorplan_from_polygon(Polygon(ring), name=name, rooms=rooms)


def _from_sfw_dict(data: Mapping[str, Any]) -> Floorplan:
    if data.get("version") != FORMAT_VERSION:
        raise FloorplanError(f"unsupported sfw_gym floorplan version {data.get('version')!r}")
    for key in ("free_space", "footprint", "edge_materials"):
        if key not in data:
            raise FloorplanError(f"missing key {key!r}")
    free = data["free_space"]
    if not isinstance(free, Mapping) or "exterior" not in free:
        raise FloorplanError("'free_space' must be an object with 'exterior' (and 'holes')")
    holes = free.get("holes", [])
    if not isinstance(holes, list):
        raise FloorplanError("'free_space.holes' must be a list of rings")
    shell = _parse_ring(free["exterior"], "free_space.exterior")
    hole_rings = [_parse_ring(h, f"free_space.holes[{i}]") for i, h in enumerate(holes)]
    materials = data["edge_materials"]
    if not isinstance(materials, list) or not all(isinstance(m, str) for m in materials):
        raise FloorplanError("'edge_materials' must be a list of material names")
    routers = data.get("routers", [])
    if not isinstance(routers, list):
        raise FloorplanError("'routers' must be a list of [x, y] positions")
    rooms = []
    for i, room in enumerate(data.get("rooms", [])):
        if not isinstance(room, Mapping) or "label" not in room or "box" not in room:
            raise FloorplanError(f"rooms[{i}] must be an object with 'label' and 'box'")
        rooms.append(
            Room(str(room["label"]), _box(_parse_numbers(room["box"], f"rooms[{i}].box", 4)))
        )
    return Floorplan(
        Polygon(shell, hole_rings),
        Polygon(_parse_ring(data["footprint"], "footprint")),
        tuple(materials),
        name=str(data.get("name", "floorplan")),
        rooms=tuple(rooms),
        routers=tuple(_xy(_parse_numbers(r, f"routers[{i}]", 2)) for i, r in enumerate(routers)),
    )


def chosen_routers(given: Any, plan: Floorplan | None, default: Any = None) -> Any:
    """The routers an episode on ``plan`` uses: ``given`` (a command's ``--routers``: positions
    or a count) where given, else the plan's own (:attr:`Floorplan.routers`, as ``[[x, y], ...]``),
    else ``default`` (a count, or None: the env's ``n_routers``, both placed by k-means)."""
    if given is not None:
        return given
    if plan is not None and plan.routers:
        return [list(r) for r in plan.routers]
    return default


def floorplan_files(folder: str | os.PathLike[str]) -> list[Path]:
    """A folder's plan files (:data:`PLAN_SUFFIXES`), sorted by name; a file: itself. Whether
    each loads is :func:`load_floorplan`'s to say."""
    path = Path(folder)
    if path.is_file():
        return [path]
    found = path.iterdir() if path.is_dir() else iter(())
    return sorted(p for p in found if p.suffix.lower() in PLAN_SUFFIXES and p.is_file())


def _box(v: list[float]) -> tuple[float, float, float, float]:
    return v[0], v[1], v[2], v[3]


def _xy(v: list[float]) -> tuple[float, float]:
    return v[0], v[1]


def _parse_numbers(values: Any, what: str, n: int) -> list[float]:
    if not isinstance(values, list | tuple) or len(values) != n:
        raise FloorplanError(f"{what} must be a list of {n} numbers, got {values!r:.80}")
    out = []
    for v in values:
        if isinstance(v, bool) or not isinstance(v, int | float):
            raise FloorplanError(f"{what} must hold numbers, got {v!r:.40}")
        out.append(float(v))
    return out


def _parse_ring(verts: Any, what: str) -> np.ndarray:
    if not isinstance(verts, list):
        raise FloorplanError(
            f"{what} must be a list of [x, y] vertices, got {type(verts).__name__}"
        )
    pts = np.array([_parse_numbers(v, f"{what}[{i}]", 2) for i, v in enumerate(verts)], np.float64)
    if len(pts) and np.array_equal(pts[0], pts[-1]):
        pts = pts[:-1]  # a closed ring: drop the repeated vertex
    if len(pts) < 3:
        raise FloorplanError(f"{what} has {len(pts)} distinct vertices; a polygon needs at least 3")
    if not np.isfinite(pts).all():
        raise FloorplanError(f"{what} contains NaN or infinite coordinates")
    return pts


def _n_vertices(poly: Polygon) -> int:
    return len(poly.exterior.coords) + sum(len(r.coords) for r in poly.interiors)


def _check_polygon(poly: Any, what: str, name: str) -> None:
    if not isinstance(poly, Polygon):
        raise FloorplanError(f"floorplan {name!r}: {what} must be a shapely Polygon")
    if poly.is_empty or poly.area <= 0:
        raise FloorplanError(f"floorplan {name!r}: {what} has zero area")
    n_vertices = _n_vertices(poly)
    if n_vertices > MAX_VERTICES:
        raise FloorplanError(
            f"floorplan {name!r}: {what} has {n_vertices:,} vertices, over the {MAX_VERTICES:,} "
            "the simulation takes (simplify the outline, e.g. shapely's simplify(0.01))"
        )
    coords = np.asarray(poly.exterior.coords)
    if not np.isfinite(coords).all():
        raise FloorplanError(f"floorplan {name!r}: {what} contains NaN or infinite coordinates")
    if not poly.is_valid:
        raise FloorplanError(
            f"floorplan {name!r}: {what} is not a simple polygon ({explain_validity(poly)})"
        )
    xmin, ymin, xmax, ymax = poly.bounds
    extent = max(xmax - xmin, ymax - ymin)
    if not MIN_EXTENT_M <= extent <= MAX_EXTENT_M or max(map(abs, poly.bounds)) > 10 * MAX_EXTENT_M:
        raise FloorplanError(
            f"floorplan {name!r}: {what} spans {extent:.3g} m at {poly.bounds}; expected a "
            f"building of {MIN_EXTENT_M:g}–{MAX_EXTENT_M:g} m in metres (wrong units?)"
        )
    if poly.area < MIN_AREA_M2:
        raise FloorplanError(
            f"floorplan {name!r}: {what} has an area of {poly.area:.3g} m² (< {MIN_AREA_M2} m²)"
        )


def _ring_coords(ring: Any) -> list[list[float]]:
    return [[float(x), float(y)] for x, y in list(ring.coords)[:-1]]


def _polygon_edges(poly: Polygon) -> np.ndarray:
    """(E, 4) edges of all rings of ``poly`` in ring order, closing vertex excluded."""
    parts = []
    for ring in [poly.exterior, *poly.interiors]:
        pts = np.asarray(ring.coords, dtype=np.float64)
        parts.append(np.hstack([pts[:-1], pts[1:]]))
    return np.ascontiguousarray(np.vstack(parts))
