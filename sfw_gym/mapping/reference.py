"""The SfW authors' mapping method, as a baseline (``method="sfw-reference"``).

Reconstructed from the paper's Alg. 2 (Kim et al., arXiv 2408.07757) and the behaviour of the
authors' public script, which is much simpler than the paper's full method (no k-means, no Eq. 6,
no fusion over routers):

1. every sample is attributed to the strongest router (the *focused* router: the strongest of
   the row's readings);
2. its k-value comes from fixed RSSI thresholds, −41 and −56 dBm: ``k = 0`` above the first,
   ``1`` above the second, else ``2``;
3. along the router → robot segment every cell moves by ±15 (of 0 … 255, 127 unknown): ``+15``
   (towards free) for ``k = 0`` (rule 2), ``−15`` (towards wall) for ``k ≥ 1`` (rule 3);
4. an earlier sample of the same pass on the same ray (within half a cell of it) with the same
   focused router and k frees the stretch between the two (rule 4, ``+15``);
5. the robot's own cell is set free (255, rule 1);
6. the log is run forward and then reversed over the same map.

Cells are the grid's cells (the authors' canvas pixels are 0.0115 m; a map at 0.05 m moves each
cell by the same ±15). The cost is quadratic in the samples per router (rule 4 looks at every
earlier sample), which the authors' logs (a few thousand rows) never noticed.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from sfw_gym.core.constants import NOT_HEARD_DBM
from sfw_gym.core.errors import ConfigError
from sfw_gym.mapping.grid import GridSpec

#: The authors' fixed thresholds, dBm: k = 0 above the first, 1 above the second, else 2.
REFERENCE_THRESHOLDS_DBM = (-41.0, -56.0)
#: The authors' change per cell and observation (of 0 … 255).
REFERENCE_STEP = 15


@njit(cache=True)
def _add_line(img, r0, c0, r1, c1, delta):
    """Add ``delta`` (clipped to 0 … 255) to the cells of the Bresenham line r0,c0 → r1,c1."""
    h, w = img.shape
    dr, dc = abs(r1 - r0), abs(c1 - c0)
    sr = 1 if r1 > r0 else -1
    sc = 1 if c1 > c0 else -1
    err = dc - dr
    r, c = r0, c0
    for _ in range(max(dr, dc) + 1):  # the line's cells: one per step along its longer axis
        if 0 <= r < h and 0 <= c < w:
            img[r, c] = min(255, max(0, img[r, c] + delta))
        e2 = 2 * err
        if e2 > -dr:
            err -= dr
            c += sc
        if e2 < dc:
            err += dc
            r += sr


@njit(cache=True)
def _reference_pass(img, order, cells, pos, focus, k, routers, router_cells, origin, res, step):
    n = order.size
    tol = 0.5 * res
    done = np.empty(n, np.int64)  # the samples of this pass so far
    n_done = 0
    for idx in range(n):
        i = order[idx]
        r = focus[i]
        if r < 0:
            continue
        rr, rc = router_cells[r, 0], router_cells[r, 1]
        _add_line(img, rr, rc, cells[i, 0], cells[i, 1], step if k[i] == 0 else -step)
        # rule 4: earlier samples on this ray with the same router and k
        ux, uy = pos[i, 0] - routers[r, 0], pos[i, 1] - routers[r, 1]
        length = np.hypot(ux, uy)
        if length > 0:
            ux /= length
            uy /= length
            t_lo, t_hi = length, length
            for j in range(n_done):
                o = done[j]
                if focus[o] != r or k[o] != k[i]:
                    continue
                vx, vy = pos[o, 0] - routers[r, 0], pos[o, 1] - routers[r, 1]
                t = vx * ux + vy * uy
                if t > 0 and abs(vx * uy - vy * ux) <= tol:
                    t_lo = min(t_lo, t)
                    t_hi = max(t_hi, t)
            if t_hi > t_lo:
                ends = np.empty((2, 2), np.int64)  # [row, col] of the stretch's two ends
                for e, t in enumerate((t_lo, t_hi)):
                    ends[e, 0] = int(np.floor((routers[r, 1] + t * uy - origin[1]) / res))
                    ends[e, 1] = int(np.floor((routers[r, 0] + t * ux - origin[0]) / res))
                _add_line(img, ends[0, 0], ends[0, 1], ends[1, 0], ends[1, 1], step)
        img[cells[i, 0], cells[i, 1]] = 255
        done[n_done] = i
        n_done += 1


def sfw_reference_map(
    grid: GridSpec,
    routers_m,
    positions_m,
    rssi_dbm,
    *,
    thresholds_dbm: tuple[float, float] = REFERENCE_THRESHOLDS_DBM,
    step: int = REFERENCE_STEP,
) -> np.ndarray:
    """The authors' map of a log (module docstring): uint8, 0 wall … 127 unknown … 255 free.

    Args:
        grid: The map's grid; every position and router must lie in it.
        routers_m: ``(R, 2)`` router positions, metres.
        positions_m: ``(N, 2)`` sample positions, metres.
        rssi_dbm: ``(N, R)`` each router's RSSI per sample; ``-100`` or less: not heard.
        thresholds_dbm: The two fixed thresholds (descending).
        step: Change per cell and observation.

    Raises:
        ConfigError: On mismatched shapes, non-finite values, or a point outside the grid.
    """
    routers = np.asarray(routers_m, np.float64).reshape(-1, 2)
    pos = np.asarray(positions_m, np.float64)
    rssi = np.asarray(rssi_dbm, np.float64)
    if pos.ndim != 2 or pos.shape[1] != 2 or rssi.shape != (len(pos), len(routers)):
        raise ConfigError(
            f"positions_m must be (N, 2) and rssi_dbm (N, R={len(routers)}), got {pos.shape} "
            f"and {rssi.shape}"
        )
    if not (np.isfinite(pos).all() and np.isfinite(rssi).all() and np.isfinite(routers).all()):
        raise ConfigError("positions, routers and RSSI must be finite (-100 dBm: not heard)")
    t1, t2 = thresholds_dbm
    if not t1 > t2:
        raise ConfigError(f"thresholds_dbm must be descending, got {thresholds_dbm}")
    cells = _cells(grid, pos, "a position")
    router_cells = _cells(grid, routers, "a router")
    strongest = rssi.max(axis=1) if len(pos) else np.empty(0)
    focus = np.where(strongest > NOT_HEARD_DBM, rssi.argmax(axis=1) if len(pos) else 0, -1)
    k = np.where(strongest > t1, 0, np.where(strongest > t2, 1, 2)).astype(np.int64)
    img = np.full(grid.shape, 127, np.int64)
    origin = np.asarray(grid.origin_xy, np.float64)
    forward = np.arange(len(pos), dtype=np.int64)
    for order in (forward, forward[::-1].copy()):
        _reference_pass(
            img, order, cells, pos, focus.astype(np.int64), k, routers, router_cells, origin,
            float(grid.resolution_m), int(step),
        )  # fmt: skip
    return img.astype(np.uint8)


def _cells(grid: GridSpec, points: np.ndarray, what: str) -> np.ndarray:
    """``(N, 2)`` [row, col] of each point; ConfigError for a point outside the grid."""
    rc = np.floor((points[:, ::-1] - np.asarray(grid.origin_xy)[::-1]) / grid.resolution_m)
    rc = rc.astype(np.int64)
    outside = (rc < 0).any(axis=1) | (rc >= np.asarray(grid.shape)).any(axis=1)
    if outside.any():
        i = int(np.flatnonzero(outside)[0])
        raise ConfigError(f"{what} at {points[i].tolist()} lies outside the map's grid")
    return rc
