"""Dense inverse k-visibility (Alg. 1 of Kim et al.): the oracle map from the true k of every cell.

Along every ray from the router the k-value never decreases, and it steps up exactly where the
ray crosses a wall (never at a shadow line, which runs along the rays). Every cell with a known
k (``k >= 0``) is free space; the oracle walks from it towards the router and, wherever two
successive cells with a known k differ, marks the wall between them: the cells without a known
k in between (``k < 0``, e.g. the wall's own cells) if any, else the farther of the two cells.
Walls win over free; cells with unknown k that no ray marks stay unknown (127).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from sfw_gym.core.constants import U8_FREE, U8_UNKNOWN, U8_WALL
from sfw_gym.core.errors import ConfigError
from sfw_gym.mapping.grid import GridSpec
from sfw_gym.mapping.raycast import ray_buffer_size, traverse_grid


@njit(cache=True)
def _dense_kernel(k_grid, rgx, rgy, adjacent, wall, free, rows, cols, t0, t1):
    n_rows, n_cols = k_grid.shape
    for i in range(n_rows):
        for j in range(n_cols):
            if k_grid[i, j] < 0:
                continue
            free[i, j] = True
            n = traverse_grid(j + 0.5, i + 0.5, rgx, rgy, n_rows, n_cols, rows, cols, t0, t1)
            last = 0  # index of the last cell with a known k, walking towards the router
            k_last = k_grid[i, j]
            for m in range(1, n):
                k = k_grid[rows[m], cols[m]]
                if k < 0:
                    continue
                if k != k_last:
                    if m - last > 1:
                        for q in range(last + 1, m):
                            wall[rows[q], cols[q]] = True
                    elif adjacent:
                        wall[rows[last], cols[last]] = True
                last = m
                k_last = k


def dense_inverse_k_visibility(
    grid: GridSpec, router_xy, k_grid, *, adjacent_steps: bool = True
) -> np.ndarray:
    """Oracle map from the true k-value of every cell (Alg. 1).

    Args:
        grid: Map geometry.
        router_xy: Router ``(x, y)`` in metres, or ``(R, 2)`` for several routers.
        k_grid: int ``grid.shape`` array of k-values (``< 0`` = unknown, e.g. inside walls or
            outside the plan), or ``(R, *grid.shape)`` with one layer per router.
        adjacent_steps: Whether a step in k between two neighbouring cells on a ray (no cell
            of unknown k between them) marks the farther one (Alg. 1). On a rasterised plan,
            where every wall has cells of its own, such steps only occur along shadow lines
            (a cell centre just inside the shadow, its ray grazing cells just outside): False
            ignores them, which makes the oracle a fair reference for map metrics.

    Returns:
        uint8 map: 0 wall, 255 free, 127 unknown. With several routers a cell is a wall if any
        router's rays mark it, else free if any marks it free.
    """
    if not isinstance(grid, GridSpec):
        raise ConfigError(f"grid must be a GridSpec, got {type(grid).__name__}")
    routers = np.asarray(router_xy, dtype=np.float64)
    k = np.asarray(k_grid)
    if routers.shape == (2,):
        routers = routers[None]
        k = k[None] if k.ndim == 2 else k
    if routers.ndim != 2 or routers.shape[1] != 2 or not np.isfinite(routers).all():
        raise ConfigError(f"router_xy must be finite (x, y) or (R, 2), got shape {routers.shape}")
    if k.shape != (routers.shape[0], *grid.shape):
        raise ConfigError(
            f"k_grid must have shape {grid.shape} (one router) or (R, *{grid.shape}), "
            f"got {np.asarray(k_grid).shape} for {routers.shape[0]} router(s)"
        )
    if not np.issubdtype(k.dtype, np.integer):
        raise ConfigError(f"k_grid must be an integer array, got dtype {k.dtype}")
    k = k.astype(np.int64)
    wall = np.zeros(grid.shape, np.bool_)
    free = np.zeros(grid.shape, np.bool_)
    size = ray_buffer_size(grid.shape)
    rows = np.empty(size, np.int64)
    cols = np.empty(size, np.int64)
    t0 = np.empty(size, np.float64)
    t1 = np.empty(size, np.float64)
    g = grid.world_to_grid(routers)
    for r in range(routers.shape[0]):
        _dense_kernel(k[r], g[r, 0], g[r, 1], bool(adjacent_steps), wall, free, rows, cols, t0, t1)
    out = np.full(grid.shape, U8_UNKNOWN, np.uint8)
    out[free] = U8_FREE
    out[wall] = U8_WALL
    return out
