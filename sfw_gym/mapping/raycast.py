"""Compiled grid ray traversal (Amanatides & Woo, 1987), clipped to the grid.

The kernel works in continuous grid coordinates: ``gx = (x - origin_x) / resolution_m`` (the
column axis) and ``gy`` likewise (the row axis); cell ``(row, col)`` spans
``[col, col + 1) x [row, row + 1)``. It lists every cell whose interior the segment passes
through, in order from start to end. Where the segment passes exactly through a cell corner it
steps diagonally (the two side cells are only touched at a point); a cell touched only at the
segment's end point is not listed.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from sfw_gym.core.errors import ConfigError
from sfw_gym.mapping.grid import GridSpec

_TIE_EPS = 1e-10


@njit(cache=True)
def _clip_to_box(x0, y0, dx, dy, w, h):
    """Liang-Barsky clip of ``p0 + t * d, t in [0, 1]`` to ``[0, w] x [0, h]``."""
    t_lo = 0.0
    t_hi = 1.0
    for i in range(4):
        if i == 0:
            p, q = -dx, x0
        elif i == 1:
            p, q = dx, w - x0
        elif i == 2:
            p, q = -dy, y0
        else:
            p, q = dy, h - y0
        if p == 0.0:
            if q < 0.0:
                return 1.0, 0.0
        else:
            r = q / p
            if p < 0.0:
                if r > t_lo:
                    t_lo = r
            elif r < t_hi:
                t_hi = r
    return t_lo, t_hi


@njit(cache=True)
def _axis_steps(p0, d, cell):
    """One axis of the traversal from ``p0`` moving ``d`` per unit ``t``, in ``cell``: the step
    (+1, -1 or 0), the ``t`` one cell takes and the ``t`` at which the first cell border is
    crossed (``inf`` when the segment does not move along the axis)."""
    if d > 0.0:
        return 1, 1.0 / d, (cell + 1 - p0) / d
    if d < 0.0:
        return -1, -1.0 / d, (cell - p0) / d
    return 0, np.inf, np.inf


@njit(cache=True)
def traverse_grid(x0, y0, x1, y1, n_rows, n_cols, out_rows, out_cols, out_t0, out_t1):
    """Cells crossed by a segment, in order, clipped to the grid.

    Args:
        x0, y0, x1, y1: Segment end points in continuous grid coordinates (x = column axis).
        n_rows, n_cols: Grid shape.
        out_rows, out_cols: int buffers receiving the cells (size >= ``n_rows + n_cols``).
        out_t0, out_t1: float buffers receiving the segment parameter ``t`` in ``[0, 1]`` at which
            the segment enters and leaves each cell.

    Returns:
        The number of cells written.
    """
    dx = x1 - x0
    dy = y1 - y0
    t_lo, t_hi = _clip_to_box(x0, y0, dx, dy, float(n_cols), float(n_rows))
    if t_lo > t_hi:
        return 0
    cap = out_rows.shape[0]
    px = x0 + t_lo * dx
    py = y0 + t_lo * dy
    col = int(np.floor(px))
    row = int(np.floor(py))
    col = min(max(col, 0), n_cols - 1)
    row = min(max(row, 0), n_rows - 1)
    sx, t_dx, t_max_x = _axis_steps(x0, dx, col)
    sy, t_dy, t_max_y = _axis_steps(y0, dy, row)
    n = 0
    t_cur = t_lo
    while n < cap:
        t_next = min(t_max_x, t_max_y, t_hi)
        out_rows[n] = row
        out_cols[n] = col
        out_t0[n] = t_cur
        out_t1[n] = t_next
        n += 1
        if t_next >= t_hi:
            break
        if abs(t_max_x - t_max_y) <= _TIE_EPS:
            col += sx
            row += sy
            t_cur = t_max_x
            t_max_x += t_dx
            t_max_y += t_dy
        elif t_max_x < t_max_y:
            col += sx
            t_cur = t_max_x
            t_max_x += t_dx
        else:
            row += sy
            t_cur = t_max_y
            t_max_y += t_dy
        if col < 0 or col >= n_cols or row < 0 or row >= n_rows:
            break
    return n


def ray_buffer_size(shape: tuple[int, int]) -> int:
    """A buffer length that always holds one traversal on a grid of ``shape``."""
    return int(shape[0]) + int(shape[1]) + 2


def ray_cells(
    grid: GridSpec, start_xy, end_xy, *, return_t: bool = False
) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Every grid cell the segment ``start_xy -> end_xy`` passes through, in order.

    Args:
        grid: The grid.
        start_xy: World ``(x, y)`` of the start, metres.
        end_xy: World ``(x, y)`` of the end, metres.
        return_t: Also return the ``(N, 2)`` entry/exit parameters ``t`` in ``[0, 1]``.

    Returns:
        ``(N, 2)`` int64 array of ``(row, col)``; the part of the segment outside the grid is
        dropped. With ``return_t``, a tuple ``(cells, t)``.
    """
    a = np.asarray(start_xy, dtype=np.float64).reshape(-1)
    b = np.asarray(end_xy, dtype=np.float64).reshape(-1)
    if a.shape != (2,) or b.shape != (2,):
        raise ConfigError(f"start_xy and end_xy must be (x, y) pairs, got {start_xy!r}, {end_xy!r}")
    if not (np.isfinite(a).all() and np.isfinite(b).all()):
        raise ConfigError(f"start_xy and end_xy must be finite, got {start_xy!r}, {end_xy!r}")
    ga = grid.world_to_grid(a)
    gb = grid.world_to_grid(b)
    size = ray_buffer_size(grid.shape)
    rows = np.empty(size, np.int64)
    cols = np.empty(size, np.int64)
    t0 = np.empty(size, np.float64)
    t1 = np.empty(size, np.float64)
    n = traverse_grid(ga[0], ga[1], gb[0], gb[1], grid.n_rows, grid.n_cols, rows, cols, t0, t1)
    cells = np.stack([rows[:n], cols[:n]], axis=1)
    if return_t:
        return cells, np.stack([t0[:n], t1[:n]], axis=1)
    return cells
