"""The compiled radio-zone kernels against the vectorised numpy computations they replace:
equal bit for bit, so the agents that use them act exactly as before (issue 39)."""

from __future__ import annotations

import numpy as np
import pytest

from sfw_gym.mapping.grid import GridSpec
from sfw_gym.navigation.radio_zones import wall_crossings


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
