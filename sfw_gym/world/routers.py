"""Where routers go when the user does not say: spread out, in open spots, as a person would."""

from __future__ import annotations

import numpy as np
import shapely

from sfw_gym.core.constants import BULK_VERTICES
from sfw_gym.core.errors import ConfigError
from sfw_gym.core.threads import single_threaded_openmp
from sfw_gym.world.floorplan import Floorplan

#: Routers keep this clearance from walls (a router on a shelf, not inside the wall).
ROUTER_CLEARANCE_M = 0.3


def place_routers(floorplan: Floorplan, n: int, rng: np.random.Generator) -> np.ndarray:
    """``n`` router positions (n, 2) in open free space, each central to the part it serves.

    The free space is split into ``n`` parts by k-means over random open spots (one router serves
    a home best from its middle; two serve best from the middles of its halves), and each router
    stands at the open spot nearest its part's centre.
    """
    if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < 1:
        raise ConfigError(f"number of routers must be a positive integer, got {n!r}")
    free = floorplan.free_space
    if len(floorplan.edges) > BULK_VERTICES:  # the clearance by distance queries, not a buffer

        def is_open(pts: np.ndarray) -> np.ndarray:
            inside = shapely.contains_xy(free, pts[:, 0], pts[:, 1])
            near = shapely.dwithin(free.boundary, shapely.points(pts), ROUTER_CLEARANCE_M)
            return inside & ~near

        region = free
    else:
        region = free.buffer(-ROUTER_CLEARANCE_M)
        if region.is_empty:
            region = free

        def is_open(pts: np.ndarray) -> np.ndarray:
            return shapely.contains_xy(region, pts[:, 0], pts[:, 1])

    xmin, ymin, xmax, ymax = region.bounds
    candidates = np.empty((0, 2))
    for _ in range(50):  # rejection sampling: keep drawing until there are enough open spots
        pts = rng.uniform((xmin, ymin), (xmax, ymax), size=(512, 2))
        candidates = np.vstack([candidates, pts[is_open(pts)]])
        if len(candidates) >= 256:
            break
    if len(candidates) < n:
        raise ConfigError(f"floorplan {floorplan.name!r} has no open spot for a router")
    from sklearn.cluster import KMeans  # here: importing scikit-learn takes a second

    seed = int(rng.integers(2**31))
    with single_threaded_openmp():
        centres = KMeans(n_clusters=n, n_init=1, random_state=seed).fit(candidates).cluster_centers_
    nearest = np.argmin(np.linalg.norm(candidates[:, None] - centres[None], axis=2), axis=0)
    return candidates[nearest]


def place_background_aps(
    floorplan: Floorplan,
    n: int,
    rng: np.random.Generator,
    *,
    outside_share: float = 0.5,
    reach_m: float = 10.0,
) -> np.ndarray:
    """``n`` access points beyond the mapping routers (n, 2): about ``1 - outside_share`` of
    them in the building's free space, the others outside its footprint within ``reach_m`` of
    it (neighbouring units), uniformly. The robot does not know where they are."""
    if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < 0:
        raise ConfigError(f"number of background APs must be an integer >= 0, got {n!r}")
    xmin, ymin, xmax, ymax = floorplan.bounds
    n_out = int(rng.binomial(n, outside_share))
    found: list[np.ndarray] = []
    for inside, count, pad in ((True, n - n_out, 0.0), (False, n_out, reach_m)):
        kept = np.zeros((0, 2))
        for _ in range(200):
            if len(kept) >= count:
                break
            pts = rng.uniform((xmin - pad, ymin - pad), (xmax + pad, ymax + pad), size=(256, 2))
            shape = floorplan.free_space if inside else floorplan.footprint
            hit = shapely.contains_xy(shape, pts[:, 0], pts[:, 1])
            kept = np.vstack([kept, pts[hit if inside else ~hit]])
        if len(kept) < count:
            raise ConfigError(f"floorplan {floorplan.name!r}: no room for {count} access points")
        found.append(kept[:count])
    return np.concatenate(found)
