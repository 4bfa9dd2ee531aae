"""Observations: channel-first uint8 images of the belief map and a float32 state vector.

Everything here is what the robot knows (belief map, odometry, router positions, RSSI, bump);
nothing is ground truth.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

import numpy as np
from gymnasium import spaces
from numba import njit

from sfw_gym.core.constants import U8_UNKNOWN
from sfw_gym.mapping import GridSpec

#: RSSI is normalised as (rssi − floor) / span into [0, 1].
RSSI_FLOOR_DBM, RSSI_SPAN_DB = -100.0, 80.0
#: Channels of the global "map" image.
MAP_CHANNELS = ("belief", "trajectory_and_robot", "routers")
TRAJECTORY_U8, ROBOT_U8 = 128, 255


def observation_space(
    n_routers: int, map_px: int, crop_px: int, n_background_aps: int = 0, lidar_beams: int = 0
) -> spaces.Dict:
    """The Dict space: ``map`` (3, map_px, map_px), ``local`` (1, crop_px, crop_px), ``state``;
    with background access points also ``fingerprint`` (their RSSI scaled as the routers' in
    ``state``, 0 where not heard) and ``fingerprint_heard`` (1 where heard); with a LiDAR,
    ``lidar`` (each beam's range ÷ max range, 1 where nothing returned)."""
    entries: dict[str, spaces.Space] = {
        "map": spaces.Box(0, 255, (len(MAP_CHANNELS), map_px, map_px), np.uint8),
        "local": spaces.Box(0, 255, (1, crop_px, crop_px), np.uint8),
        "state": spaces.Box(-1.0, 1.0, (state_size(n_routers),), np.float32),
    }
    if n_background_aps:
        entries["fingerprint"] = spaces.Box(0.0, 1.0, (n_background_aps,), np.float32)
        entries["fingerprint_heard"] = spaces.Box(0, 1, (n_background_aps,), np.int8)
    if lidar_beams:
        entries["lidar"] = spaces.Box(0.0, 1.0, (lidar_beams,), np.float32)
    return spaces.Dict(entries)


def lidar_observation(ranges_m: np.ndarray, max_range_m: float) -> np.ndarray:
    """The ``lidar`` entry: ranges ÷ ``max_range_m``, 1 where a beam returned nothing."""
    return np.minimum(ranges_m / max_range_m, 1.0).astype(np.float32)


def fingerprint_observation(rssi_dbm: np.ndarray) -> dict[str, np.ndarray]:
    """The ``fingerprint`` entries for background RSSI readings (dBm; not heard at the floor)."""
    heard = rssi_dbm > RSSI_FLOOR_DBM
    scaled = np.clip((rssi_dbm - RSSI_FLOOR_DBM) / RSSI_SPAN_DB, 0.0, 1.0) * heard
    return {"fingerprint": scaled.astype(np.float32), "fingerprint_heard": heard.astype(np.int8)}


def state_size(n_routers: int) -> int:
    """Length of the state vector: RSSI and heard flag per router, bump, x, y, sin, cos, known."""
    return 2 * n_routers + 6


def map_pixels(grid: GridSpec, map_px: int, rc: np.ndarray) -> np.ndarray:
    """``(N, 2)`` grid cells → their centres' (row, col) on the ``map`` image ÷ ``map_px``
    (fractions in [0, 1]: where a policy samples image features for a cell)."""
    cells_per_px = max(grid.shape) / map_px
    pad = (map_px - np.array(grid.shape) / cells_per_px) / 2
    centre = (np.asarray(rc, np.float64).reshape(-1, 2) + 0.5) / cells_per_px
    return np.clip((centre + pad) / map_px, 0.0, 1.0).astype(np.float32)


class ObservationBuilder:
    """Builds observations for one episode's grid; precomputes the sampling indices once.

    ``map``: the whole grid fitted into map_px × map_px (aspect kept, centred, nearest-cell
    sampling; padding reads unknown). ``local``: an axis-aligned crop_px × crop_px window of the
    belief at full resolution centred on the odometry pose (outside the grid reads unknown).
    """

    def __init__(
        self, grid: GridSpec, routers_xy: np.ndarray, n_router_slots: int, map_px: int, crop_px: int
    ) -> None:
        self.grid = grid
        self.map_px = map_px
        self.crop_px = crop_px
        self.n_router_slots = n_router_slots
        rows, cols = grid.shape
        # the grid's geometry as plain floats (read every step)
        (self._ox, self._oy), self._res = grid.origin_xy, grid.resolution_m
        self._rows, self._cols = rows, cols
        self._width_m, self._height_m = cols * grid.resolution_m, rows * grid.resolution_m
        self.cells_per_px = max(rows, cols) / map_px
        pad_r = (map_px - rows / self.cells_per_px) / 2
        pad_c = (map_px - cols / self.cells_per_px) / 2
        src_r = np.floor((np.arange(map_px) - pad_r + 0.5) * self.cells_per_px).astype(np.int64)
        src_c = np.floor((np.arange(map_px) - pad_c + 0.5) * self.cells_per_px).astype(np.int64)
        valid = ((src_r >= 0) & (src_r < rows))[:, None] & ((src_c >= 0) & (src_c < cols))[None, :]
        self._src_r, self._src_c = np.clip(src_r, 0, rows - 1), np.clip(src_c, 0, cols - 1)
        self._pad = ~valid
        self._pad_r, self._pad_c = pad_r, pad_c
        self._trajectory = np.zeros((map_px, map_px), np.uint8)
        self._routers = np.zeros((map_px, map_px), np.uint8)
        for x, y in routers_xy:
            r, c = self.pixel_of(x, y)
            self._routers[max(r - 1, 0) : r + 2, max(c - 1, 0) : c + 2] = 255
        self._routers_xy = np.asarray(routers_xy, np.float64)

    def pixel_of(self, x: float, y: float) -> tuple[int, int]:
        """Map-image pixel (row, col) of a world point, clamped to the image."""
        r = math.floor((y - self._oy) / self._res / self.cells_per_px + self._pad_r)
        c = math.floor((x - self._ox) / self._res / self.cells_per_px + self._pad_c)
        return min(max(r, 0), self.map_px - 1), min(max(c, 0), self.map_px - 1)

    def image_of(self, grid_u8: np.ndarray) -> np.ndarray:
        """A ``(rows, cols)`` uint8 grid sampled onto the map image (padding reads unknown)."""
        image = grid_u8[np.ix_(self._src_r, self._src_c)]
        image[self._pad] = U8_UNKNOWN
        return image

    def clear_visited(self) -> None:
        """Empty the trajectory channel (before drawing a corrected trajectory)."""
        self._trajectory.fill(0)

    def mark_visited(self, x: float, y: float) -> None:
        """Add a pose to the trajectory channel."""
        r, c = self.pixel_of(x, y)
        self._trajectory[r, c] = TRAJECTORY_U8

    def build(
        self,
        belief_u8: np.ndarray,
        rssi_dbm: Iterable[float],
        bumped: bool,
        odometry_pose: tuple[float, float, float],
        known_fraction: float,
    ) -> dict[str, np.ndarray]:
        """The observation dict for the current belief and readings (``rssi_dbm``: one per router
        slot, dBm)."""
        x, y, theta = odometry_pose
        r, c = self.pixel_of(x, y)
        cr = min(max(int((y - self._oy) / self._res), 0), self._rows - 1)
        cc = min(max(int((x - self._ox) / self._res), 0), self._cols - 1)
        image, local = _draw(
            belief_u8, self._src_r, self._src_c, self._pad, self._trajectory, self._routers,
            (r, c, cr, cc), self.crop_px,
        )  # fmt: skip

        slots = self.n_router_slots
        state = [0.0] * state_size(slots)  # a few numbers: plain floats, one conversion
        for i, dbm in enumerate(rssi_dbm):
            if dbm > RSSI_FLOOR_DBM:
                state[i] = min(max((dbm - RSSI_FLOOR_DBM) / RSSI_SPAN_DB, 0.0), 1.0)
                state[slots + i] = 1.0
        state[2 * slots :] = (
            float(bumped),
            min(max((x - self._ox) / self._width_m, 0.0), 1.0),
            min(max((y - self._oy) / self._height_m, 0.0), 1.0),
            math.sin(theta),
            math.cos(theta),
            known_fraction,
        )
        return {"map": image, "local": local, "state": np.array(state, np.float32)}


@njit(cache=True)
def _draw(
    belief: np.ndarray,
    src_r: np.ndarray,
    src_c: np.ndarray,
    pad: np.ndarray,
    trajectory: np.ndarray,
    routers: np.ndarray,
    robot_at: tuple[int, int, int, int],
    crop: int,
) -> tuple[np.ndarray, np.ndarray]:
    """The ``map`` image (the belief sampled at ``src_r × src_c``, unknown on ``pad``; the
    trajectory with the robot's 3 × 3 square at its pixel; the routers) and the ``local`` crop
    of the belief centred on its cell (unknown outside the grid), in one pass. ``robot_at``:
    the robot's map-image pixel (row, col) and belief cell (row, col)."""
    m = src_r.shape[0]
    image = np.empty((3, m, m), np.uint8)
    local = np.empty((1, crop, crop), np.uint8)
    for i in range(m):
        row = belief[src_r[i]]
        out = image[0, i]
        padded = pad[i]
        for j in range(m):
            out[j] = U8_UNKNOWN if padded[j] else row[src_c[j]]
    draw_rest_into(belief, trajectory, routers, robot_at, crop, image, local)
    return image, local


@njit(cache=True)
def draw_rest_into(
    belief: np.ndarray,
    trajectory: np.ndarray,
    routers: np.ndarray,
    robot_at: tuple[int, int, int, int],
    crop: int,
    image: np.ndarray,
    local: np.ndarray,
) -> None:
    """Write every part of :func:`_draw`'s ``map`` image but its belief channel ``image[0]``
    (the caller's), and the ``local`` crop."""
    r, c, cr, cc = robot_at
    copy_into(image[1], trajectory)
    copy_into(image[2], routers)
    image[1, max(r - 1, 0) : r + 2, max(c - 1, 0) : c + 2] = ROBOT_U8
    rows, cols = belief.shape
    half = crop // 2
    flat_local = local.reshape(-1)
    for k in range(flat_local.shape[0]):
        flat_local[k] = U8_UNKNOWN
    c0 = cc - half  # belief column of the crop's first column
    j0, j1 = max(0, -c0), min(crop, cols - c0)  # the crop's columns inside the grid
    for i in range(crop):
        br = cr + i - half
        if 0 <= br < rows and j0 < j1:
            out = local[0, i]
            row = belief[br]
            for j in range(j0, j1):
                out[j] = row[c0 + j]


@njit(cache=True)
def copy_into(dst: np.ndarray, src: np.ndarray) -> None:
    """``dst[...] = src`` for C-contiguous arrays of one shape, as one flat loop (numba's
    array assignment steps through every dimension, several times slower)."""
    flat_dst = dst.reshape(-1)
    flat_src = src.reshape(-1)
    for k in range(flat_dst.shape[0]):
        flat_dst[k] = flat_src[k]
