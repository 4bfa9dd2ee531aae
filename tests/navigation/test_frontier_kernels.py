"""The compiled frontier kernels against references written with scipy.ndimage: the frontier
kept up to date where the belief changed, and the clusters in their documented order."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

from sfw_gym.navigation.frontiers import cluster_cells, frontier_mask, update_frontier

W, U, F = 0, 127, 255


def random_belief(rng: np.random.Generator, shape=(9, 11)) -> np.ndarray:
    """Walls, unknown and free cells (and values between the classes' bounds) everywhere,
    the grid's edges included."""
    return rng.choice(
        np.array([W, 40, U, 200, F], np.uint8), size=shape, p=[0.2, 0.1, 0.4, 0.1, 0.2]
    )


def reference_clusters(mask: np.ndarray, min_size: int) -> list[list[tuple[int, int]]]:
    """8-connected clusters by scipy's labelling, largest first, ties by label (the order of
    their first cell in raster order), cells in raster order."""
    labels, n = ndimage.label(mask, structure=np.ones((3, 3), bool))
    groups = [list(zip(*np.nonzero(labels == k), strict=True)) for k in range(1, n + 1)]
    order = sorted(range(n), key=lambda k: (-len(groups[k]), k))
    return [[(int(r), int(c)) for r, c in groups[k]] for k in order if len(groups[k]) >= min_size]


@pytest.mark.parametrize("seed", range(6))
def test_the_frontier_updated_where_the_belief_changed_is_the_frontier_of_the_new_belief(seed):
    rng = np.random.default_rng(seed)
    before = random_belief(rng)
    after = before.copy()
    changed = rng.choice(after.size, size=12, replace=False)
    after.flat[changed] = random_belief(rng, (12,))
    seen, frontier = before.copy(), frontier_mask(before)
    update_frontier(after, seen, np.sort(changed).astype(np.int64), frontier)
    np.testing.assert_array_equal(seen, after)
    free = after >= 200  # U8_FREE_MIN: 200 is free, 40 a wall
    unknown = (after > 40) & (after < 200)
    expected = unknown & ndimage.binary_dilation(free, structure=np.ones((3, 3), bool))
    np.testing.assert_array_equal(frontier, expected)


def test_a_free_cell_on_the_first_row_makes_its_unknown_neighbours_below_frontier_cells():
    belief = np.full((3, 3), U, np.uint8)
    belief[0, 0] = F
    frontier = np.zeros((3, 3), bool)
    update_frontier(belief, belief.copy(), np.arange(9, dtype=np.int64), frontier)
    assert np.argwhere(frontier).tolist() == [[0, 1], [1, 0], [1, 1]]


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("min_size", [1, 2, 4])
def test_clusters_are_scipys_labels_largest_first_ties_in_label_order(seed, min_size):
    mask = np.random.default_rng(seed).random((12, 14)) < 0.3
    got = [[tuple(c) for c in cells.tolist()] for cells in cluster_cells(mask, min_size)]
    assert got == reference_clusters(mask, min_size)


def test_many_clusters_of_one_size_keep_their_raster_order():
    """More ties than a sort's insertion-sort cut-off (16): a stable sort keeps their order."""
    mask = np.zeros((10, 30), bool)
    mask[0:8:2, ::2] = True  # 60 single cells, apart
    mask[9, 1:3] = True  # one pair, numbered after them: it still comes first
    got = [cells.tolist() for cells in cluster_cells(mask)]
    assert got[0] == [[9, 1], [9, 2]]
    assert [cell for (cell,) in got[1:]] == np.argwhere(mask[:8]).tolist()
