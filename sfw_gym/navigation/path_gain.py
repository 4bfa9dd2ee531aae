"""What a path buys: the readings a robot would take along the first steps of a
planned path, the k a map gives each, and the best-prefix rate that ranks them.

- :func:`readings_along`: one reading per control step, turns in place charged in steps (the
  robot turns ``turn_per_step_rad`` per step, then moves ``step_m`` per step along the path).
- :func:`walls_crossed`: per reading, the walls of a wall mask between it and its router (runs of
  wall cells on the ray): the k that a mapper would read there if the mask were the plan.
- :func:`best_prefix_rate`: the most bits per step over any prefix of at least ``min_steps``
  steps (a receding-horizon next-best-view score: appending steps that gain nothing leaves it
  unchanged, so it does not favour long paths the way a sum along the path does).

The bits themselves come from the mapper's own update run dry
(:class:`~sfw_gym.mapping.dry_run.DryRun`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from sfw_gym.mapping.grid import GridSpec
from sfw_gym.mapping.raycast import ray_buffer_size, traverse_grid
from sfw_gym.navigation.planning import densify_path


def readings_along(
    path_xy: np.ndarray,
    pose: tuple[float, float, float],
    step_m: float,
    turn_per_step_rad: float,
    horizon: int,
) -> np.ndarray:
    """Where the robot reads, step by step, driving ``path_xy`` ``(N, 2)`` from ``pose``: a
    reading after each step, ``horizon`` of them at most (fewer where the path ends).

    A change of heading of ``a`` radians costs ``floor(a / turn_per_step_rad)`` steps in place
    (a reading each, where the robot stands) before the robot moves on.
    """
    pts = densify_path(np.asarray(path_xy, np.float64).reshape(-1, 2), step_m)
    out = np.empty((horizon, 2))
    x, y, heading = float(pose[0]), float(pose[1]), float(pose[2])
    n = 0
    for px, py in pts.tolist():
        if n >= horizon:
            break
        d = math.hypot(px - x, py - y)
        if d < 1e-9:
            continue
        bearing = math.atan2(py - y, px - x)
        turn = abs(math.remainder(bearing - heading, math.tau))
        for _ in range(min(int(turn / turn_per_step_rad), horizon - n)):
            out[n] = x, y
            n += 1
        heading = bearing
        if n < horizon:
            x, y = px, py
            out[n] = x, y
            n += 1
    return out[:n]


def walls_crossed(
    grid: GridSpec, walls: np.ndarray, routers_xy: np.ndarray, router: np.ndarray, xy: np.ndarray
) -> np.ndarray:
    """Per reading at ``xy`` ``(N, 2)``, the runs of ``walls`` (bool ``(H, W)``) cells on the ray
    from its router (``routers_xy[router]``) to it (int ``(N,)``; 0 where ``router`` is -1)."""
    xy = np.asarray(xy, np.float64).reshape(-1, 2)
    g = grid.world_to_grid(xy)
    rg = grid.world_to_grid(np.asarray(routers_xy, np.float64).reshape(-1, 2))
    n = ray_buffer_size(grid.shape)
    return _walls_crossed(
        np.ascontiguousarray(walls, np.bool_),
        rg,
        np.asarray(router, np.int64).reshape(-1),
        g,
        np.empty(n, np.int64),
        np.empty(n, np.int64),
        np.empty(n),
        np.empty(n),
    )


@njit(cache=True)
def _walls_crossed(walls, routers_g, router, g, rows, cols, t0, t1):  # pragma: no cover
    n_rows, n_cols = walls.shape
    out = np.zeros(len(g), np.int64)
    for i in range(len(g)):
        r = router[i]
        if r < 0:
            continue
        m = traverse_grid(
            routers_g[r, 0], routers_g[r, 1], g[i, 0], g[i, 1], n_rows, n_cols, rows, cols, t0, t1
        )
        inside = False
        for j in range(m):
            w = walls[rows[j], cols[j]]
            if w and not inside:
                out[i] += 1
            inside = w
    return out


def best_prefix_rate(gains: np.ndarray, starts: np.ndarray, min_steps: int) -> np.ndarray:
    """Per path (``gains`` ``(N,)`` bits per step, the paths one after another from ``starts``),
    ``max over m >= min_steps of sum(gains[:m]) / m``; a path shorter than ``min_steps`` is
    charged ``min_steps`` steps (0 for an empty one)."""
    gains = np.asarray(gains, np.float64)
    bounds = np.append(np.asarray(starts, np.int64), len(gains))
    out = np.zeros(len(bounds) - 1)
    for c in range(len(out)):
        g = gains[bounds[c] : bounds[c + 1]]
        if not len(g):
            continue
        m = np.arange(1, len(g) + 1)
        rate = np.cumsum(g) / np.maximum(m, min_steps)
        out[c] = rate[min(min_steps, len(g)) - 1 :].max()
    return out


def path_totals(gains: np.ndarray, starts: np.ndarray) -> np.ndarray:
    """Per path (as :func:`best_prefix_rate` takes them), the total of its bits."""
    cum = np.concatenate([[0.0], np.cumsum(np.asarray(gains, np.float64))])
    bounds = np.append(np.asarray(starts, np.int64), len(cum) - 1)
    return cum[bounds[1:]] - cum[bounds[:-1]]
