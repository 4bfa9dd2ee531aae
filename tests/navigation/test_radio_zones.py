"""The compiled radio-zone kernels against the vectorised numpy computations they replace:
equal bit for bit, so the agents that use them act exactly as before (issue 39)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import cKDTree

from sfw_gym.core.constants import NOT_HEARD_DBM
from sfw_gym.mapping.grid import GridSpec
from sfw_gym.navigation.radio_zones import dominance_bands, router_scores, wall_crossings


def wall_crossings_numpy(grid, walls, sources_xy, points_xy):
    """The vectorised computation ``wall_crossings`` replaced (float32 samples)."""
    src = np.asarray(sources_xy, np.float64).reshape(-1, 2)
    pts = np.asarray(points_xy, np.float64).reshape(-1, 2)
    out = np.zeros((len(pts), len(src)), np.int64)
    if not walls.any() or len(pts) == 0:
        return out
    h, w = walls.shape
    padded = np.zeros((h + 2, w + 2), bool)
    padded[1:-1, 1:-1] = walls
    flat_walls = padded.ravel()
    origin = np.asarray(grid.origin_xy)
    src_g = (src - origin) / grid.resolution_m + 1.0
    pts_g = (pts - origin) / grid.resolution_m + 1.0
    for r, s0 in enumerate(src_g):
        n = max(2, int(np.ceil(np.linalg.norm(pts_g - s0, axis=1).max() / 0.7)) + 1)
        t = np.linspace(0.0, 1.0, n, dtype=np.float32)
        d = (pts_g - s0).astype(np.float32)
        cx = np.clip(s0[0] + d[:, None, 0] * t, 0, w + 1).astype(np.int32)
        cy = np.clip(s0[1] + d[:, None, 1] * t, 0, h + 1).astype(np.int32)
        hit = flat_walls[cy * (w + 2) + cx]
        out[:, r] = (hit[:, 1:] & ~hit[:, :-1]).sum(axis=1) + hit[:, 0]
    return out


def random_case(rng):
    """A random grid, wall mask, sources and points (some beyond the grid, some on cell edges)."""
    h, w = (int(v) for v in rng.integers(1, 60, 2))
    res = float(rng.choice([0.05, 0.07, 0.1, 0.25]))
    grid = GridSpec(origin_xy=tuple(rng.uniform(-3, 3, 2)), resolution_m=res, shape=(h, w))
    walls = rng.random((h, w)) < rng.uniform(0.0, 0.5)
    lo = np.asarray(grid.origin_xy) - 1.0
    hi = lo + 2.0 + np.array([w, h]) * res
    sources = rng.uniform(lo, hi, (int(rng.integers(1, 4)), 2))
    points = rng.uniform(lo, hi, (int(rng.integers(0, 50)), 2))
    if rng.random() < 0.3:
        points = np.round(points / res * 2.0) * res / 2.0
    return grid, walls, sources, points


@pytest.mark.parametrize("seed", range(4))
def test_wall_crossings_equal_the_vectorised_float32_sampling(seed):
    rng = np.random.default_rng(seed)
    for _ in range(300):
        grid, walls, sources, points = random_case(rng)
        np.testing.assert_array_equal(
            wall_crossings(grid, walls, sources, points),
            wall_crossings_numpy(grid, walls, sources, points),
        )


def router_scores_numpy(grid, routers_xy, samples_xy, samples_rssi, walls, wall_loss_db=10.0):
    """The vectorised ``router_scores`` (defaults: n = 2, 2 m residual radius, coarse 2,
    600 samples), its wall term from ``wall_crossings``."""
    xs, ys = grid.cell_centres()
    cells = np.stack([xs.ravel(), ys.ravel()], axis=1)
    routers = np.asarray(routers_xy, np.float64).reshape(-1, 2)

    def distance_term(points):
        d = np.linalg.norm(points[:, None, :] - routers[None, :, :], axis=2)
        return -10.0 * 2.0 * np.log10(np.maximum(d, 1.0))

    scores = distance_term(cells)
    use_walls = bool(walls.any()) and wall_loss_db > 0
    if use_walls:
        h, w = grid.shape
        sub = np.stack([xs[::2, ::2].ravel(), ys[::2, ::2].ravel()], axis=1)
        n_w = wall_crossings(grid, walls, routers, sub).reshape(*xs[::2, ::2].shape, -1)
        n_w = np.repeat(np.repeat(n_w, 2, axis=0), 2, axis=1)[:h, :w]
        scores -= wall_loss_db * n_w.reshape(-1, len(routers))
    pts, rssi = samples_xy, samples_rssi
    if len(pts) > 600:
        keep = np.linspace(0, len(pts) - 1, 600).astype(int)
        pts, rssi = pts[keep], rssi[keep]
    model = distance_term(pts)
    if use_walls:
        model -= wall_loss_db * wall_crossings(grid, walls, routers, pts)
    resid = rssi - model
    heard = rssi > NOT_HEARD_DBM
    if heard.any():
        resid = resid - float(np.median(resid[heard]))
    k = min(8, len(pts))
    dist, idx = cKDTree(pts).query(cells, k=k, distance_upper_bound=2.0)
    dist, idx = dist.reshape(len(cells), k), idx.reshape(len(cells), k)
    found = np.isfinite(dist)
    idx = np.where(found, idx, 0)
    for r in range(routers.shape[0]):
        if not heard[:, r].any():
            scores[:, r] = -np.inf
            continue
        e = np.where(heard[:, r], resid[:, r], 0.0)
        weight = np.where(found & heard[idx, r], 1.0 / (dist + 0.3) ** 2, 0.0)
        wsum = weight.sum(axis=1)
        scores[:, r] += np.where(
            wsum > 0, (weight * e[idx]).sum(axis=1) / np.maximum(wsum, 1e-12), 0.0
        )
    return scores.T.reshape(routers.shape[0], *grid.shape)


@pytest.mark.parametrize("seed", range(4))
def test_router_scores_equal_the_vectorised_computation_bit_for_bit(seed):
    """Random walks (some standing still: equal distances; some off the map), some routers never
    heard, fewer and more than 8 (and 600) samples, with and without walls; signed zeros
    compared too."""
    rng = np.random.default_rng(seed)
    for _ in range(25):
        h, w = (int(v) for v in rng.integers(5, 50, 2))
        grid = GridSpec(origin_xy=(0.0, 0.0), resolution_m=0.1, shape=(h, w))
        routers = rng.uniform(0.0, 0.1 * np.array([w, h]), (int(rng.integers(1, 4)), 2))
        steps = rng.normal(0.0, 0.1, (int(rng.choice([1, 5, 8, 40, 700])), 2))
        steps[rng.random(len(steps)) < 0.3] = 0.0
        samples = np.clip(0.05 * np.array([w, h]) + np.cumsum(steps, axis=0), 0.0, None)
        if rng.random() < 0.1:
            samples += 50.0  # off the map: no cell has a sample in reach
        rssi = rng.uniform(-90.0, -30.0, (len(samples), len(routers)))
        rssi[rng.random(rssi.shape) < 0.2] = NOT_HEARD_DBM
        if rng.random() < 0.2:
            rssi[:, 0] = NOT_HEARD_DBM
        walls = rng.random((h, w)) < rng.choice([0.0, 0.05, 0.2])
        expected = router_scores_numpy(grid, routers, samples, rssi, walls)
        got = router_scores(grid, routers, samples, rssi, walls=walls)
        assert got.tobytes() == expected.tobytes()


@pytest.mark.parametrize("axis", [0, 1])
def test_the_band_follows_a_zone_border_whichever_way_it_runs(axis):
    """Two routers' zones split at row (or column) 10 of a 20 × 20 grid: the band holds every
    cell within 3 cells of the border, along its whole length."""
    near = np.zeros((20, 20))
    near[10:] = 1.0  # router 1 strongest from row 10 on
    scores = np.stack([near, 1.0 - near]) if axis else np.stack([1.0 - near, near])
    if axis:
        scores = scores.transpose(0, 2, 1)  # the border runs along a column instead
    zone, band = dominance_bands(scores, band_cells=3)
    lines = band if axis == 0 else band.T
    assert (lines[6:14].all(axis=1)).all() and not lines[:6].any() and not lines[14:].any()
    assert zone.max() == 1 and (zone == 1).sum() == 200
    flat = np.stack([near, near])  # equal everywhere: one zone, no border, no band
    assert not dominance_bands(flat, band_cells=3)[1].any()
