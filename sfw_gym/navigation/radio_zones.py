"""Router dominance zones the robot predicts from its own map and readings.

The sparse mapper updates cells only along the strongest router's ray, so the borders between
routers' dominance zones stay unknown unless the robot crosses them. These functions predict
every router's RSSI at every cell (a multi-wall log-distance model on the belief map, corrected
by the robot's own readings) and find the zones and the bands along their borders.
"""

from __future__ import annotations

import functools

import numpy as np
from numba import njit
from scipy import ndimage
from scipy.spatial import cKDTree

from sfw_gym.core.constants import NOT_HEARD_DBM
from sfw_gym.mapping.grid import GridSpec


def wall_crossings(
    grid: GridSpec, walls: np.ndarray, sources_xy: np.ndarray, points_xy: np.ndarray
) -> np.ndarray:
    """Believed walls crossed by each segment source→point: ``(P, R)`` int.

    The segment is sampled every 0.7 cell; each run of wall cells along it counts once.
    """
    src = np.asarray(sources_xy, np.float64).reshape(-1, 2)
    pts = np.asarray(points_xy, np.float64).reshape(-1, 2)
    out = np.zeros((len(pts), len(src)), np.int64)
    if not walls.any() or len(pts) == 0:
        return out
    h, w = walls.shape
    padded = np.zeros((h + 2, w + 2), bool)  # a free border: samples outside read "no wall"
    padded[1:-1, 1:-1] = walls
    origin = np.asarray(grid.origin_xy)
    src_g = (src - origin) / grid.resolution_m + 1.0  # grid coordinates (x, y) in ``padded``
    pts_g = (pts - origin) / grid.resolution_m + 1.0
    for r, s0 in enumerate(src_g):
        n = max(2, int(np.ceil(np.linalg.norm(pts_g - s0, axis=1).max() / 0.7)) + 1)
        _count_wall_runs(padded, s0, pts_g, np.linspace(0.0, 1.0, n, dtype=np.float32), out[:, r])
    return out


@njit(cache=True)
def _count_wall_runs(padded, s0, pts_g, t, out):  # pragma: no cover (compiled)
    """Per point: the runs of wall cells of ``padded`` at the samples ``s0 + (p − s0) · t``.

    The arithmetic is float32 offsets times float32 ``t``, added to the float64 source and
    clipped into the grid: the sample cells of the vectorised reference in the tests.
    """
    h2, w2 = padded.shape
    x0, y0 = s0[0], s0[1]
    for i in range(len(pts_g)):
        dx = np.float32(pts_g[i, 0] - x0)
        dy = np.float32(pts_g[i, 1] - y0)
        runs = 0
        was_wall = False
        for j in range(len(t)):
            x = min(max(x0 + np.float64(dx * t[j]), 0.0), w2 - 1.0)
            y = min(max(y0 + np.float64(dy * t[j]), 0.0), h2 - 1.0)
            is_wall = padded[int(y), int(x)]
            if is_wall and not was_wall:
                runs += 1
            was_wall = is_wall
        out[i] = runs


def router_scores(
    grid: GridSpec,
    routers_xy: np.ndarray,
    samples_xy: np.ndarray | None = None,
    samples_rssi: np.ndarray | None = None,
    *,
    walls: np.ndarray | None = None,
    wall_loss_db: float = 10.0,
    path_loss_exponent: float = 2.0,
    residual_radius_m: float = 2.0,
    coarse_cells: int = 2,
    max_samples: int = 600,
) -> np.ndarray:
    """Predicted RSSI (dBm, up to a common constant) of every router at every cell.

    The multi-wall log-distance model ``c − 10 n log10(max(d, 1 m)) − wall_loss_db · walls``
    (walls: runs of believed-wall cells on the segment router→cell; one tx power for all
    routers); with samples, each router's residuals at the samples (readings minus the model,
    minus their common median) are spread to cells within ``residual_radius_m`` by
    inverse-distance weighting (what the robot measured beats what it predicts).

    Args:
        grid: The map geometry.
        routers_xy: ``(R, 2)`` router positions.
        samples_xy: ``(T, 2)`` positions of the readings (the robot's odometry).
        samples_rssi: ``(T, R)`` readings, dBm (``NOT_HEARD_DBM`` when not heard).
        walls: Optional ``[row, col]`` mask of believed walls.
        wall_loss_db: Loss per wall in the model (a prior: the robot cannot know it).
        path_loss_exponent: ``n``.
        residual_radius_m: Reach of a reading's residual.
        coarse_cells: The wall term is evaluated every this many cells (speed).
        max_samples: At most this many (evenly spread) readings are used.

    Returns:
        ``(R, n_rows, n_cols)`` float64.
    """
    routers = np.asarray(routers_xy, np.float64).reshape(-1, 2)
    wall_mask = np.zeros(grid.shape, bool) if walls is None else np.asarray(walls, bool)
    use_walls = bool(wall_mask.any()) and wall_loss_db > 0
    scores = _cells_distance_term(grid, routers.tobytes(), float(path_loss_exponent)).copy()
    if use_walls:
        xs, ys = grid.cell_centres()
        k = max(1, int(coarse_cells))
        h, w = grid.shape
        sub = np.stack([xs[::k, ::k].ravel(), ys[::k, ::k].ravel()], axis=1)
        n_w = wall_crossings(grid, wall_mask, routers, sub).reshape(*xs[::k, ::k].shape, -1)
        n_w = np.repeat(np.repeat(n_w, k, axis=0), k, axis=1)[:h, :w]
        scores -= wall_loss_db * n_w.reshape(-1, len(routers))
    if samples_xy is not None and samples_rssi is not None and len(samples_xy):
        pts = np.asarray(samples_xy, np.float64).reshape(-1, 2)
        rssi = np.asarray(samples_rssi, np.float64).reshape(len(pts), -1)
        if len(pts) > max_samples:
            keep = np.linspace(0, len(pts) - 1, max_samples).astype(int)
            pts, rssi = pts[keep], rssi[keep]
        model = _distance_term(pts, routers, path_loss_exponent)
        if use_walls:
            model -= wall_loss_db * wall_crossings(grid, wall_mask, routers, pts)
        resid = rssi - model
        heard = rssi > NOT_HEARD_DBM
        if heard.any():
            resid = resid - float(np.median(resid[heard]))  # routers share one tx power
        xs, ys = grid.cell_centres()
        k = min(8, len(pts))
        dist, idx = cKDTree(pts).query(
            np.stack([xs.ravel(), ys.ravel()], axis=1), k=k, distance_upper_bound=residual_radius_m
        )
        dist, idx = dist.reshape(-1, k), idx.reshape(-1, k)
        for r in range(routers.shape[0]):
            if heard[:, r].any():
                e = np.where(heard[:, r], resid[:, r], 0.0)
                _add_spread_residuals(scores[:, r], dist, idx, heard[:, r], e)
            else:
                scores[:, r] = -np.inf
    return scores.T.reshape(routers.shape[0], *grid.shape)


def _distance_term(points: np.ndarray, routers: np.ndarray, exponent: float) -> np.ndarray:
    """``−10 n log10(max(d, 1 m))`` from every router to every point: ``(P, R)``."""
    d = np.linalg.norm(points[:, None, :] - routers[None, :, :], axis=2)
    return -10.0 * exponent * np.log10(np.maximum(d, 1.0))


@functools.lru_cache(maxsize=16)
def _cells_distance_term(grid: GridSpec, routers_bytes: bytes, exponent: float) -> np.ndarray:
    """:func:`_distance_term` at every cell centre (row-major), kept per map and routers."""
    xs, ys = grid.cell_centres()
    routers = np.frombuffer(routers_bytes, np.float64).reshape(-1, 2)
    term = _distance_term(np.stack([xs.ravel(), ys.ravel()], axis=1), routers, exponent)
    term.flags.writeable = False
    return term


@njit(cache=True)
def _add_spread_residuals(scores, dist, idx, heard, e):  # pragma: no cover (compiled)
    """``scores[i] +=`` the inverse-distance weighted mean of ``e`` over cell i's heard nearest
    samples (weights ``1 / (d + 0.3)²``; 0 without any), summed in numpy's order (pairwise
    over 8 neighbours, else in sequence) so the sums equal the vectorised computation's."""
    k = dist.shape[1]
    weight = np.empty(k)
    weighted = np.empty(k)
    for i in range(len(scores)):
        for j in range(k):
            found = np.isfinite(dist[i, j])
            s = idx[i, j] if found else 0
            weight[j] = (
                1.0 / ((dist[i, j] + 0.3) * (dist[i, j] + 0.3)) if found and heard[s] else 0.0
            )
            weighted[j] = weight[j] * e[s]
        total = _numpy_sum(weight)
        scores[i] += _numpy_sum(weighted) / max(total, 1e-12) if total > 0 else 0.0


@njit(cache=True)
def _numpy_sum(values):  # pragma: no cover (compiled)
    """``values.sum()`` as numpy adds up a row of up to 8 (8: pairwise, fewer: in sequence)."""
    if len(values) == 8:
        v = values
        return 0.0 + (((v[0] + v[1]) + (v[2] + v[3])) + ((v[4] + v[5]) + (v[6] + v[7])))
    total = 0.0
    for x in values:
        total += x
    return total


def dominance_bands(scores: np.ndarray, band_cells: float) -> tuple[np.ndarray, np.ndarray]:
    """The strongest router per cell and the cells within ``band_cells`` of a zone border.

    Args:
        scores: ``(R, H, W)`` predicted RSSI per router.
        band_cells: Half-width of the band, in cells.

    Returns:
        ``(zone, band)``: ``(H, W)`` int router index, ``(H, W)`` bool.
    """
    zone = np.argmax(scores, axis=0)
    border = np.zeros(zone.shape, bool)
    border[:-1, :] |= zone[:-1, :] != zone[1:, :]
    border[1:, :] |= zone[1:, :] != zone[:-1, :]
    border[:, :-1] |= zone[:, :-1] != zone[:, 1:]
    border[:, 1:] |= zone[:, 1:] != zone[:, :-1]
    if not border.any():
        return zone, border
    band = ndimage.distance_transform_edt(~border) <= band_cells
    return zone, band
