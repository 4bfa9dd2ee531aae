"""Frontier clusters of a belief map, computed by hand."""

from __future__ import annotations

import numpy as np

from sfw_gym.navigation import find_frontiers

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
