"""The wall-crossing kernels on a hand-made plan whose answers are read off the drawing (issue 53).

Free space: the room [0, 10] x [0, 4] m with a solid block [4, 5] x [1, 3] m in it (a hole of the
free-space polygon: a 1 m thick wall). Every edge has its own loss, so the loss a crossing reports
names the edge it entered by.
"""

from __future__ import annotations

import numpy as np
import pytest

from sfw_gym.world.wall_crossing import DEFAULT_MIN_PIECE_M, cross_walls, cross_walls_parallel

EDGES = np.array(
    [
        [0.0, 0.0, 10.0, 0.0],  # 0..3: the room's outline
        [10.0, 0.0, 10.0, 4.0],
        [10.0, 4.0, 0.0, 4.0],
        [0.0, 4.0, 0.0, 0.0],
        [4.0, 1.0, 4.0, 3.0],  # 4: the block's west face
        [4.0, 3.0, 5.0, 3.0],  # 5: north
        [5.0, 3.0, 5.0, 1.0],  # 6: east
        [5.0, 1.0, 4.0, 1.0],  # 7: south
    ]
)
LOSS = np.array([100.0, 101.0, 102.0, 103.0, 4.0, 5.0, 6.0, 7.0])


def crossed(a, b):
    counts, losses = cross_walls(EDGES, LOSS, np.array(a, float), np.array(b, float), 0.02)
    return counts.tolist(), losses.tolist()


def test_through_the_block_is_one_wall_with_the_loss_of_the_face_entered():
    assert crossed([(1.0, 2.0)], [(9.0, 2.0)]) == ([1], [4.0])  # west face
    assert crossed([(9.0, 2.0)], [(1.0, 2.0)]) == ([1], [6.0])  # east face
    assert crossed([(4.5, 0.5)], [(4.5, 3.5)]) == ([1], [7.0])  # south face
    assert crossed([(1.0, 2.0)], [(3.0, 2.0)]) == ([0], [0.0])  # short of it


@pytest.mark.parametrize("y", [1.0, 3.0])
def test_a_segment_along_a_wall_face_crosses_nothing(y):
    """The boundary is free space (module docstring): along the block's south and north faces,
    and along the room's outline, no wall."""
    assert crossed([(1.0, y)], [(9.0, y)]) == ([0], [0.0])
    assert crossed([(4.0, y)], [(5.0, y)]) == ([0], [0.0])  # exactly the face
    assert crossed([(1.0, 0.0)], [(9.0, 0.0)]) == ([0], [0.0])


def test_one_answer_per_segment_for_any_number_of_segments():
    a = [(1.0, 2.0), (9.0, 2.0), (1.0, 2.0)]
    b = [(9.0, 2.0), (1.0, 2.0), (3.0, 2.0)]
    assert crossed(a, b) == ([1, 1, 0], [4.0, 6.0, 0.0])
    assert crossed(a[:1], b[:1]) == ([1], [4.0])


def test_the_parallel_kernel_equals_the_serial_one_over_several_chunks():
    """1,100 random segments: two full chunks of 512 and a partial one."""
    rng = np.random.default_rng(7)
    a = rng.uniform((0.0, 0.0), (10.0, 4.0), (1100, 2))
    b = rng.uniform((0.0, 0.0), (10.0, 4.0), (1100, 2))
    counts, losses = cross_walls(EDGES, LOSS, a, b, DEFAULT_MIN_PIECE_M)
    p_counts, p_losses = cross_walls_parallel(EDGES, LOSS, a, b, DEFAULT_MIN_PIECE_M)
    assert p_counts.dtype == np.int32 and p_counts.shape == (1100,)
    np.testing.assert_array_equal(p_counts, counts)
    np.testing.assert_array_equal(p_losses, losses)
    assert set(counts.tolist()) == {0, 1}  # a segment meets the block once at most
    through = counts == 1
    assert through.sum() > 50
    # a face's loss, or 0 for a segment with both ends in the block (no face crossed)
    assert set(losses[through].tolist()) <= {0.0, 4.0, 5.0, 6.0, 7.0}
    assert (losses[~through] == 0.0).all()


def test_an_edge_is_indexed_in_exactly_the_buckets_its_arc_meets():
    """Seen from the origin, buckets are arcs of pi / 8 (0.393 rad): an edge spanning angles
    0.01..0.02 rad lies in bucket 0 only; one spanning 0.35..0.45 rad in buckets 0 and 1."""
    from sfw_gym.world.wall_index import _bucket_span

    edges = np.array(
        [
            [10.0, 10.0 * np.tan(0.01), 10.0, 10.0 * np.tan(0.02)],
            [10.0, 10.0 * np.tan(0.35), 10.0, 10.0 * np.tan(0.45)],
        ]
    )
    assert _bucket_span(edges, 0, 0.0, 0.0, 8) == (0, 1)
    assert _bucket_span(edges, 1, 0.0, 0.0, 8) == (0, 2)
