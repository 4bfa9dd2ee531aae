"""Where routers go when the user does not say: spread out, in open spots, as a person would."""

from __future__ import annotations

import numpy as np
import shapely

from sfw_gym.errors import ConfigError
from sfw_gym.world.floorplan import Floorplan

#: Routers keep this clearance from walls (a router on a shelf, not inside the wall).
ROUTER_CLEARANCE_M = 0.3


def place_routers(floorplan: Floorplan, n: int, rng: np.random.Generator) -> np.ndarray:
    """``n`` router positions (n, 2) in free space, spread by farthest-point sampling.

    The first router stands near the middle of the plan (where one router serves a home best),
    each next one as far as possible from those placed, among random open spots.
    """
    if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < 1:
        raise ConfigError(f"number of routers must be a positive integer, got {n!r}")
    region = floorplan.free_space.buffer(-ROUTER_CLEARANCE_M)
    if region.is_empty:
        region = floorplan.free_space
    xmin, ymin, xmax, ymax = region.bounds
    candidates = np.empty((0, 2))
    for _ in range(50):  # rejection sampling: keep drawing until there are enough open spots
        pts = rng.uniform((xmin, ymin), (xmax, ymax), size=(512, 2))
        candidates = np.vstack([candidates, pts[shapely.contains_xy(region, pts[:, 0], pts[:, 1])]])
        if len(candidates) >= 128:
            break
    if len(candidates) == 0:
        raise ConfigError(f"floorplan {floorplan.name!r} has no open spot for a router")
    centre = np.asarray(floorplan.free_space.centroid.coords[0])
    chosen = [candidates[np.argmin(np.linalg.norm(candidates - centre, axis=1))]]
    while len(chosen) < n:
        dist = np.min(np.linalg.norm(candidates[:, None] - np.array(chosen)[None], axis=2), axis=1)
        chosen.append(candidates[np.argmax(dist)])
    return np.array(chosen)
