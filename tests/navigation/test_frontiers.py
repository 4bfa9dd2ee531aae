"""Frontier clusters of a belief map, computed by hand."""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from sfw_gym.navigation import find_frontiers
from sfw_gym.navigation.frontiers import hidden_rooms

W, U, F = 0, 127, 255


def test_one_free_cell_has_its_eight_unknown_neighbours_as_one_frontier():
    belief = np.full((5, 5), U, np.uint8)
    belief[2, 2] = F
    (frontier,) = find_frontiers(belief)
    assert frontier.size == 8
    assert frontier.centroid_rc == (2.0, 2.0)


def test_clusters_below_the_minimum_size_leave_no_frontier_at_all():
    belief = np.full((5, 5), U, np.uint8)
    belief[2, 2] = F
    assert find_frontiers(belief, min_size_cells=9) == []
    assert find_frontiers(np.full((4, 4), U, np.uint8)) == []


def test_hidden_room_depth_is_the_distance_to_the_nearest_known_cell():
    """A 7×7 unknown room inside free space: its centre is 4 cells from the nearest known cell,
    and the depths equal a distance transform of the whole map (the room's box is enough)."""
    belief = np.full((20, 30), F, np.uint8)
    belief[5:12, 10:17] = U
    belief[0, :] = belief[:, 0] = W
    belief[0, 0] = U  # unknown outside the free cells' box does not count
    depth = hidden_rooms(belief, min_depth_cells=1.0)
    assert depth[8, 13] == 4.0 and depth[5, 10] == 1.0 and depth[0, 0] == 0.0
    unknown = belief == U
    unknown[0, 0] = False
    assert np.array_equal(depth, ndimage.distance_transform_edt(unknown))
    assert np.array_equal(
        hidden_rooms(belief, 3.0) > 0, ndimage.distance_transform_edt(unknown) >= 3
    )
