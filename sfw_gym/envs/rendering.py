"""Frames of SfW-Explore: ground truth with trajectory and rays on the left, belief on the right."""

from __future__ import annotations

import itertools
from typing import TYPE_CHECKING, Any

import numpy as np
from skimage.draw import disk, line

if TYPE_CHECKING:
    from sfw_gym.envs.explore import SfWExploreEnv

TARGET_HEIGHT_PX = 360
GREY = {0: (30, 30, 30), 127: (150, 150, 150), 255: (255, 255, 255)}
ROUTER, ROBOT, PATH, ODOM, RAY = (
    (220, 40, 40),
    (30, 160, 60),
    (60, 90, 220),
    (240, 150, 30),
    (250, 210, 0),
)


def draw_frame(env: SfWExploreEnv) -> np.ndarray:
    """An (H, W, 3) uint8 frame: truth | belief, rows flipped so that +y points up."""
    s = env.scene
    assert s is not None
    truth = s.truth_u8
    scale = max(1, round(TARGET_HEIGHT_PX / truth.shape[0]))
    left = _grey_rgb(truth)
    right = _grey_rgb(env.mapper.occupancy_u8)
    grid = env.grid

    def px(xy: np.ndarray) -> np.ndarray:
        rc = grid.world_to_grid(np.atleast_2d(xy))[:, ::-1] * scale
        return rc

    left = np.kron(left, np.ones((scale, scale, 1), np.uint8))
    right = np.kron(right, np.ones((scale, scale, 1), np.uint8))
    h, _w = left.shape[:2]
    robot_rc = px(np.array(s.robot.pose[:2]))[0]
    odom_rc = px(np.array(s.robot.odometry_pose[:2]))[0]
    for rc in px(s.radio.routers):  # rays from every router to the robot, then the routers
        _line(left, rc, robot_rc, RAY)
    for panel, path, colour in (
        (left, env.trajectory, PATH),
        (right, env.odometry_trajectory, ODOM),
    ):
        pts = px(np.array(path))
        for a, b in itertools.pairwise(pts):
            _line(panel, a, b, colour)
    for panel in (left, right):
        for rc in px(s.radio.routers):
            _disk(panel, rc, 2.5 * scale / 2 + 2, ROUTER)
    _disk(left, robot_rc, env.robot_config.radius_m / grid.resolution_m * scale, ROBOT)
    _disk(right, odom_rc, env.robot_config.radius_m / grid.resolution_m * scale, ROBOT)
    gap = np.full((h, 4, 3), 255, np.uint8)
    return np.ascontiguousarray(np.concatenate([left, gap, right], axis=1)[::-1])


def _grey_rgb(u8: np.ndarray) -> np.ndarray:
    rgb = np.repeat(u8[..., None], 3, axis=2).astype(np.uint8)
    rgb[u8 <= 84] = GREY[0]
    rgb[(u8 > 84) & (u8 < 171)] = GREY[127]
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
