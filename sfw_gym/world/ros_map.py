"""ROS map_server maps (a YAML file and its image) as floorplans.

The YAML holds ``image`` (relative to the YAML's folder, or absolute), ``resolution`` (metres per
pixel), ``origin`` (``[x, y, yaw]``: the pose of the image's bottom-left corner; yaw must be 0),
``negate``, ``occupied_thresh`` and ``free_thresh`` (map_server's meaning: a pixel of grey ``v``
is occupied with probability ``p = (255 - v) / 255``, or ``v / 255`` when negated; ``p >
occupied_thresh`` is a wall, ``p < free_thresh`` free, anything between unknown and not free).
Colour images are read as the mean of their colour channels (alpha ignored), as map_server does.

The plan's free space is the largest 4-connected region of free pixels, its holes the rest inside
it, traced along the pixel edges: exact, but where two pixels of one side touch only at a corner,
that corner is cut (by 0.35 px at most) to keep the outline simple. ``occupied_thresh`` splits
walls from unknown pixels, which are both not free here: it is checked, but does not change the
plan.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import numpy as np
from scipy import ndimage
from shapely.geometry import Polygon

from sfw_gym.core.errors import FloorplanError

#: The suffixes that mark a floorplan file as a ROS map's YAML.
ROS_MAP_SUFFIXES = (".yaml", ".yml")
#: The keys a ROS map's YAML must have (map_server's, ROS 1 and Nav2).
REQUIRED_KEYS = ("image", "resolution", "origin", "negate", "occupied_thresh", "free_thresh")
#: map_server's ``mode`` values whose free / occupied split is the thresholds' (``raw`` is not).
MODES = ("trinary", "scale")


def ros_map_free_space(path: str | os.PathLike[str], max_bytes: int) -> Polygon:
    """The free space (metres) of a ROS map_server map (its YAML file, at most ``max_bytes``;
    see the module doc); :func:`sfw_gym.world.floorplan.load_floorplan` makes it a plan.

    Raises:
        FloorplanError: one line naming the file and the problem.
    """
    where = str(path) if str(path).isprintable() else repr(str(path))
    try:
        return _load(Path(path), max_bytes)
    except FloorplanError as exc:
        raise FloorplanError(f"{where}: {exc}") from None


def free_pixels(gray: np.ndarray, negate: bool, free_thresh: float) -> np.ndarray:
    """Which pixels of a grey image (0-255) map_server calls free."""
    p = gray / 255.0 if negate else (255.0 - gray) / 255.0
    return p < free_thresh


def largest_free_polygon(free: np.ndarray) -> Polygon:
    """The largest 4-connected component of ``free`` ([row, col]) as a polygon in pixel units:
    x = column, y = rows up from the image's bottom edge (row 0 at the top)."""
    from skimage.measure import find_contours

    labels, n = ndimage.label(free)  # the default structure: 4-connected
    if n == 0:
        raise FloorplanError("no free pixel (check negate and free_thresh)")
    sizes = np.bincount(labels.ravel())[1:]
    mask = np.pad(labels == 1 + int(np.argmax(sizes)), 1).astype(np.float64)
    # marching squares at 0.5: each vertex the midpoint of a pixel edge, the free side
    # 4-connected ("low" fully connected), so two regions that touch at a corner stay apart
    rings = [_staircase(c, mask) for c in find_contours(mask, 0.5, fully_connected="low")]
    rings.sort(key=lambda r: -abs(_area(r)))
    # padded [row, col] -> pixel units (the padded row 1 is the image's top row)
    xy = [np.column_stack([r[:, 1] - 0.5, free.shape[0] - r[:, 0] + 0.5]) for r in rings]
    return Polygon(xy[0], xy[1:])


def _load(path: Path, max_bytes: int) -> Polygon:
    import yaml

    try:
        size = path.stat().st_size
        if size > max_bytes:
            raise FloorplanError(f"{size:,} bytes, over the {max_bytes:,} a map YAML may have")
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError) as exc:  # ValueError: a NUL in the name
        raise FloorplanError(f"cannot read the map YAML: {exc}") from None
    except yaml.YAMLError as exc:
        raise FloorplanError(f"not valid YAML: {' '.join(str(exc).split())}") from None
    if not isinstance(data, dict):
        raise FloorplanError(f"expected a YAML mapping, got {type(data).__name__}")
    missing = [k for k in REQUIRED_KEYS if k not in data]
    if missing:
        raise FloorplanError(f"missing key(s) {missing} of a ROS map ({', '.join(REQUIRED_KEYS)})")
    mode = data.get("mode", "trinary")
    if mode not in MODES:
        raise FloorplanError(f"mode {mode!r} is not supported; known: {list(MODES)}")
    resolution = _number(data["resolution"], "resolution")
    if resolution <= 0:
        raise FloorplanError(f"resolution must be > 0 metres per pixel, got {resolution:g}")
    occupied = _number(data["occupied_thresh"], "occupied_thresh")
    free_t = _number(data["free_thresh"], "free_thresh")
    if not (0.0 <= free_t < occupied <= 1.0):
        raise FloorplanError(
            f"thresholds must satisfy 0 <= free_thresh < occupied_thresh <= 1, got "
            f"free_thresh {free_t:g}, occupied_thresh {occupied:g}"
        )
    origin = data["origin"]
    if not isinstance(origin, list) or len(origin) != 3:
        raise FloorplanError(f"origin must be [x, y, yaw], got {origin!r:.80}")
    ox, oy, yaw = (_number(v, "origin") for v in origin)
    if yaw != 0.0:
        raise FloorplanError(f"origin yaw {yaw:g} is not supported: rotate the image to yaw 0")
    negate = data["negate"]
    if negate not in (0, 1):  # True and False too
        raise FloorplanError(f"negate must be 0 or 1, got {negate!r:.40}")
    image = data["image"]
    if not isinstance(image, str) or not image:
        raise FloorplanError(f"image must be a file name, got {image!r:.80}")
    gray = _read_gray(path.parent / image)  # an absolute image path replaces the folder
    pixels = largest_free_polygon(free_pixels(gray, bool(negate), free_t))
    # pixel units -> metres about the origin: (x, y) * resolution + origin
    return Polygon(
        np.asarray(pixels.exterior.coords) * resolution + (ox, oy),
        [np.asarray(r.coords) * resolution + (ox, oy) for r in pixels.interiors],
    )


def _number(value: Any, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise FloorplanError(f"{what} must be a finite number, got {value!r:.40}")
    return float(value)


def _read_gray(image: Path) -> np.ndarray:
    """The image as float grey levels 0-255 ([row, col], row 0 the top)."""
    from PIL import Image

    if not image.is_file():
        raise FloorplanError(f"image {str(image)!r} not found")
    try:  # PNG, PGM, ...: Pillow's formats; a palette image as its colours
        with Image.open(image) as img:
            pixels = np.asarray(img.convert("RGBA") if img.mode in ("P", "PA") else img)
    except Exception as exc:  # any of Pillow's errors: an unreadable image
        first = (str(exc).splitlines() or [type(exc).__name__])[0]
        raise FloorplanError(f"cannot read image {str(image)!r}: {first}") from None
    if pixels.dtype == np.int32 and pixels.min() >= 0 and pixels.max() <= 65535:
        pixels = pixels.astype(np.uint16)  # 16-bit grey as older Pillow opens it (mode "I")
    if pixels.dtype == np.bool_:
        scale = 255.0
    elif pixels.dtype == np.uint8:
        scale = 1.0
    elif pixels.dtype == np.uint16:
        scale = 255.0 / 65535.0
    else:
        raise FloorplanError(f"image {str(image)!r}: unsupported pixel type {pixels.dtype}")
    if pixels.ndim == 3 and pixels.shape[2] in (2, 3, 4):  # grey+alpha, RGB, RGBA
        pixels = pixels[..., : 1 if pixels.shape[2] == 2 else 3].mean(axis=2)
    if pixels.ndim != 2 or min(pixels.shape) < 1:
        raise FloorplanError(f"image {str(image)!r}: expected one 2-D image, got {pixels.shape}")
    return pixels.astype(np.float64) * scale


def _staircase(contour: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """A marching-squares contour (edge midpoints, [row, col]) turned into the pixel edges it
    follows: the pixel corner between two consecutive midpoints is put back, unless that corner
    is a saddle (two pixels of one side touching only there), whose cut keeps the ring simple."""
    p = contour[:-1]  # closed: the last point repeats the first
    q = np.roll(p, -1, axis=0)
    p_row_half = np.abs(p[:, 0] - np.floor(p[:, 0]) - 0.5) < 0.25
    q_row_half = np.abs(q[:, 0] - np.floor(q[:, 0]) - 0.5) < 0.25
    turn = p_row_half != q_row_half  # one midpoint on a row edge, the next on a column edge
    corner = np.where(p_row_half[:, None], np.column_stack([p[:, 0], q[:, 1]]), 0.0)
    corner = np.where(q_row_half[:, None], np.column_stack([q[:, 0], p[:, 1]]), corner)
    r0 = np.floor(corner[:, 0]).astype(np.int64)
    c0 = np.floor(corner[:, 1]).astype(np.int64)
    turn &= ~_saddle(mask, np.clip(r0, 0, mask.shape[0] - 2), np.clip(c0, 0, mask.shape[1] - 2))
    out = np.empty((len(p) + int(turn.sum()), 2))
    index = np.arange(len(p)) + np.concatenate([[0], np.cumsum(turn)[:-1]])
    out[index] = p
    out[index[turn] + 1] = corner[turn]
    return _drop_collinear(out)


def _saddle(mask: np.ndarray, r: np.ndarray, c: np.ndarray) -> np.ndarray:
    a, b = mask[r, c], mask[r, c + 1]
    d, e = mask[r + 1, c], mask[r + 1, c + 1]
    return (a == e) & (b == d) & (a != b)


def _drop_collinear(ring: np.ndarray) -> np.ndarray:
    prev, nxt = np.roll(ring, 1, axis=0), np.roll(ring, -1, axis=0)
    cross = (ring[:, 0] - prev[:, 0]) * (nxt[:, 1] - ring[:, 1]) - (ring[:, 1] - prev[:, 1]) * (
        nxt[:, 0] - ring[:, 0]
    )
    return ring[np.abs(cross) > 1e-9]


def _area(ring: np.ndarray) -> float:
    x, y = ring[:, 0], ring[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))
