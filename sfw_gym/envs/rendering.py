"""Frames of SfW-Explore: ground truth with trajectory and rays on the left, belief on the right."""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from typing import Any

import numpy as np
from skimage.draw import disk, line

from sfw_gym.core.constants import U8_FREE, U8_UNKNOWN, U8_WALL
from sfw_gym.mapping.grid import GridSpec, belief_classes

#: Panel height when frames take the plan's own size (``render_size=None``).
NATIVE_HEIGHT_PX = 360
#: Letterbox margins.
BACKGROUND = (255, 255, 255)
GREY = {U8_WALL: (30, 30, 30), U8_UNKNOWN: (150, 150, 150), U8_FREE: (255, 255, 255)}
ROUTER, ROBOT, PATH, ODOM, RAY = (
    (220, 40, 40),
    (30, 160, 60),
    (60, 90, 220),
    (240, 150, 30),
    (250, 210, 0),
)


def draw_frame(
    *,
    truth_u8: np.ndarray,
    belief_u8: np.ndarray,
    grid: GridSpec,
    routers_xy: np.ndarray,
    pose: Sequence[float],
    odometry_pose: Sequence[float],
    trajectory: Sequence[tuple[float, float]] | np.ndarray,
    odometry_trajectory: Sequence[tuple[float, float]] | np.ndarray,
    robot_radius_m: float,
    size: tuple[int, int] | None = None,
) -> np.ndarray:
    """An RGB frame: truth with the true path and rays | belief with the odometry path.

    Rows are flipped so that +y points up. With ``size=(width, height)`` the two panels are
    scaled to fit (aspect kept) and centred on a white background, so that every plan gives
    frames of the same shape (video writers need that); with ``None`` each grid cell is an
    integer number of pixels and the panels are about :data:`NATIVE_HEIGHT_PX` high.

    Returns:
        ``(height, width, 3)`` uint8.
    """
    rows, cols = truth_u8.shape
    gap_px = 4
    if size is None:
        scale = float(max(1, round(NATIVE_HEIGHT_PX / rows)))
        out_h, out_w = int(rows * scale), int(2 * cols * scale) + gap_px
    else:
        out_w, out_h = size
        scale = min(out_h / rows, (out_w - gap_px) / (2 * cols))
    panel_h, panel_w = max(1, int(rows * scale)), max(1, int(cols * scale))
    # nearest-neighbour upscaling of both maps onto the panel's pixels
    src_r = np.minimum((np.arange(panel_h) / scale).astype(np.int64), rows - 1)
    src_c = np.minimum((np.arange(panel_w) / scale).astype(np.int64), cols - 1)
    left = _grey_rgb(truth_u8)[np.ix_(src_r, src_c)]
    right = _grey_rgb(belief_u8)[np.ix_(src_r, src_c)]

    def px(xy: Any) -> np.ndarray:
        return grid.world_to_grid(np.atleast_2d(np.asarray(xy, np.float64)))[:, ::-1] * scale

    routers = px(routers_xy) if len(routers_xy) else np.zeros((0, 2))
    robot_rc, odom_rc = px(pose[:2])[0], px(odometry_pose[:2])[0]
    for rc in routers:  # rays from every router to the robot, then the routers
        _line(left, rc, robot_rc, RAY)
    for panel, path, colour in ((left, trajectory, PATH), (right, odometry_trajectory, ODOM)):
        for a, b in itertools.pairwise(px(path) if len(path) else []):
            _line(panel, a, b, colour)
    for panel in (left, right):
        for rc in routers:
            _disk(panel, rc, 2.5 * scale / 2 + 2, ROUTER)
    robot_px = robot_radius_m / grid.resolution_m * scale
    _disk(left, robot_rc, robot_px, ROBOT)
    _disk(right, odom_rc, robot_px, ROBOT)

    frame = np.empty((out_h, out_w, 3), np.uint8)
    frame[:] = BACKGROUND
    top = (out_h - panel_h) // 2
    x0 = (out_w - (2 * panel_w + gap_px)) // 2
    frame[top : top + panel_h, x0 : x0 + panel_w] = left[::-1]
    x1 = x0 + panel_w + gap_px
    frame[top : top + panel_h, x1 : x1 + panel_w] = right[::-1]
    return frame


def _grey_rgb(u8: np.ndarray) -> np.ndarray:
    _, wall, unknown = belief_classes(u8)
    rgb = np.repeat(np.asarray(u8, np.uint8)[..., None], 3, axis=2)
    rgb[wall] = GREY[U8_WALL]
    rgb[unknown] = GREY[U8_UNKNOWN]
    return rgb


def _line(img: np.ndarray, a: np.ndarray, b: np.ndarray, colour: tuple[int, int, int]) -> None:
    rr, cc = line(int(a[0]), int(a[1]), int(b[0]), int(b[1]))
    ok = (rr >= 0) & (rr < img.shape[0]) & (cc >= 0) & (cc < img.shape[1])
    img[rr[ok], cc[ok]] = colour


def _disk(img: np.ndarray, centre: np.ndarray, radius: float, colour: tuple[int, int, int]) -> None:
    rr, cc = disk((centre[0], centre[1]), max(radius, 1.5), shape=img.shape[:2])
    img[rr, cc] = colour


def show_frame(frame: np.ndarray, window: Any, fps: int) -> Any:
    """Show a frame in a matplotlib window (created on first use); returns the window state."""
    import matplotlib.pyplot as plt

    if window is None:
        fig, ax = plt.subplots(figsize=(frame.shape[1] / 100, frame.shape[0] / 100))
        ax.set_axis_off()
        image = ax.imshow(frame)
        window = (fig, image)
        plt.show(block=False)
    else:
        window[1].set_data(frame)
    window[0].canvas.draw_idle()
    plt.pause(1.0 / fps)
    return window


def close_window(window: Any) -> None:
    """Close a window made by `show_frame`."""
    import matplotlib.pyplot as plt

    plt.close(window[0])
