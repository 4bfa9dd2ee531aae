"""The sparse mapper's wall rules at their stated values, derived by hand (issue 53).

Every case lies on row 10 of a 0.1 m grid, on the horizontal ray from a router at (0.25, 1.05):
a cell ``c`` of that row has its centre at ``x = c / 10 + 0.05``, i.e. ``s = x - 0.25`` metres
from the router along the ray, and the ray enters it at ``s = c / 10 - 0.25``. Readings are
calibrated and unfiltered (thresholds K0 - 5, K0 - 15, K0 - 25 dB), so a reading is exactly the
k asked for. Eq. 6 (module docstring of :mod:`sfw_gym.mapping.sparse`) is evaluated here with
plain ``math``:

``P(s) = 0.5 + (p_peak - 0.5) * min(1, L_ref / L) * exp(-(s - mid)^2 / (2 sigma^2))``,
``sigma = max(sigma_min, sigma_fraction * L)``, the cell's log-odds ``logit(P)``.

Also the grid traversal's clipping at the grid's edges against a reference that samples the
segment densely (:func:`sfw_gym.mapping.raycast.traverse_grid`).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import replace

import numpy as np
import pytest

from sfw_gym.mapping import GridSpec, MapperConfig, SparseInverseKVisibility, belief_classes
from sfw_gym.mapping.raycast import traverse_grid

K0 = 20.0 - 40.2  # RSSI at 1 m with no wall: P_tx - PL(1 m)
WALL_DB = 10.0
GRID = GridSpec((0.0, 0.0), 0.1, (20, 60))
ROUTER = (0.25, 1.05)
EXACT = MapperConfig(filter_window=1, k0_level_dbm=K0, robot_radius_m=0.0)
PEAK, L_REF, S_FRAC, S_MIN = 0.8, 0.5, 0.15, 0.05  # MapperConfig's defaults


def rssi_k(p, k) -> list[float]:
    """The RSSI that reads as exactly k at p (free-space loss beyond 1 m, 10 dB per wall)."""
    return [K0 - 20.0 * math.log10(max(math.dist(p, ROUTER), 1.0)) - WALL_DB * k]


def logit(p: float) -> float:
    return math.log(p / (1.0 - p))


def eq6(s: float, s_a: float, s_b: float) -> float:
    """Eq. 6's log-odds at arc position ``s`` for a one-wall interval ``[s_a, s_b]`` (metres)."""
    length = s_b - s_a
    sigma = max(S_MIN, S_FRAC * length)
    amp = (PEAK - 0.5) * min(1.0, L_REF / length)
    excess = amp * math.exp(-((s - 0.5 * (s_a + s_b)) ** 2) / (2 * sigma**2))
    return logit(0.5 + excess) if excess >= 1e-3 else 0.0  # below 1e-3: the cell is skipped


def s_of(col: int) -> float:
    """Arc position of the centre of row-10 cell ``col`` from the router."""
    return col / 10 + 0.05 - ROUTER[0]


def at(col: float) -> tuple[float, float]:
    """The centre of row-10 cell ``col``."""
    return (col / 10 + 0.05, 1.05)


def mapper(**changes) -> SparseInverseKVisibility:
    return SparseInverseKVisibility(GRID, [ROUTER], replace(EXACT, **changes))


# -- wall_cap_factor --------------------------------------------------------------------------
@pytest.mark.parametrize("cap_factor", [1.0, 2.5])
def test_one_piece_lifts_a_cell_to_at_most_cap_factor_times_its_evidence(cap_factor):
    """The same reading repeated at b, one wall from a: each repeat adds logit(P(s)) to every
    cell of the piece a..b until the cell holds cap_factor * logit(P(s)); after n repeats a
    cell holds min(n, cap_factor) times what one reading gives it (log_odds_max = 4 is far)."""
    m = mapper(wall_cap_factor=cap_factor)
    a, b = at(20), at(50)
    m.update(a, rssi_k(a, 0))
    cells = slice(21, 50)
    one = None
    for n in range(1, 6):
        m.update(b, rssi_k(b, 1))
        lo = m.log_odds[10, cells].astype(np.float64)
        if one is None:
            one = lo.copy()
            # one reading: Eq. 6 on the cells between a and b, from the edge of cell 21 to
            # that of cell 49: [1.85, 4.75] m (radius 0: nothing cut off)
            want = [eq6(s_of(c), 1.85, 4.75) for c in range(21, 50)]
            lifted = one > 0
            assert lifted[10:20].all()  # the middle of the piece holds wall evidence
            assert one[lifted] == pytest.approx(np.asarray(want)[lifted], rel=1e-4)
        assert lo == pytest.approx(min(n, cap_factor) * one, rel=1e-5)
    assert m.log_odds[10, cells].max() == pytest.approx(
        cap_factor * logit(0.5 + 0.3 * 0.5 / 2.9),
        rel=1e-5,  # cell 35: s = 3.3 m, the middle
    )


# -- the wall interval shortened by the robot's radius at trajectory points ---------------------
def test_the_wall_interval_from_the_router_is_cut_only_at_the_robot_end():
    """First reading, k = 1 at b (4.8 m from the router), radius 0.2 m: the wall lies in
    [0, 4.8 - 0.2] = [0, 4.6] m (the router end is no trajectory point: not cut), so the peak
    is at 2.3 m (cell 25's centre) with height logit(0.5 + 0.3 * 0.5 / 4.6)."""
    m = mapper(robot_radius_m=0.2)
    b = at(50)
    m.update(b, rssi_k(b, 1))
    lo = m.log_odds[10].astype(np.float64)
    assert int(np.argmax(lo)) == 25
    assert lo[25] == pytest.approx(logit(0.5 + 0.3 * 0.5 / 4.6), rel=1e-5)
    for c in range(10, 41):  # away from both ends (the robot's footprint)
        assert lo[c] == pytest.approx(eq6(s_of(c), 0.0, 4.6), rel=1e-4), c


def test_the_wall_interval_between_two_trajectory_points_is_cut_at_both_ends():
    """a (k = 0) at 1.8 m, b (k = 1) at 4.8 m from the router, radius 0.2 m: the wall lies in
    [1.8 + 0.2, 4.8 - 0.2] = [2.0, 4.6] m, peak at 3.3 m (cell 35's centre), height
    logit(0.5 + 0.3 * 0.5 / 2.6). A footprint of -0.5 (not classified free) keeps the
    longest-run narrowing out of the way."""
    m = mapper(robot_radius_m=0.2, footprint_log_odds=-0.5)
    a, b = at(20), at(50)
    m.update(a, rssi_k(a, 0))
    m.update(b, rssi_k(b, 1))
    lo = m.log_odds[10].astype(np.float64)
    assert int(np.argmax(lo)) == 35
    assert lo[35] == pytest.approx(logit(0.5 + 0.3 * 0.5 / 2.6), rel=1e-5)
    for c in range(23, 48):  # outside a's and b's footprints
        assert lo[c] == pytest.approx(eq6(s_of(c), 2.0, 4.6), rel=1e-4), c


# -- the longest run of cells not known free ----------------------------------------------------
def free_cells_on_row_10(m: SparseInverseKVisibility, cols) -> None:
    """Visit (c + 0.05, 1.15), one row below the ray: the 0.1 m footprint covers the row-10 cell
    c (its centre exactly 0.1 m away) with -1.0, classified free; the visit's own ray leaves
    row 10 before cell 25 and its cell (row 11) is no trajectory point on row 10."""
    for c in cols:
        p = (c / 10 + 0.05, 1.15)
        m.update(p, rssi_k(p, 0))
    assert (belief_classes(m.occupancy_u8)[0][10, list(cols)]).all()


@pytest.mark.parametrize(
    ("free", "run", "interval", "peak"),
    [
        # runs 21..29, 31..33, 35..49: the longest comes last; its interval
        # [max(1.8 + 0.1, 3.25), min(4.8 - 0.1, 4.75)], middle 3.975 m
        ((30, 34), (35, 49), (3.25, 4.7), (41, 42)),
        # runs 21..37, 39..41, 43..49: the longest comes first; the short run 39..41 is nearer
        # the interval's middle, 3.3 m (its centre 3.8 m, the longest's 2.7 m): it must not win.
        # The wall: [max(1.9, 1.85), min(4.7, 3.55)], middle 2.725 m (cell 29's centre 2.7 m)
        ((38, 42), (21, 37), (1.9, 3.55), (29,)),
    ],
)
def test_one_wall_goes_in_the_longest_run_of_cells_not_known_free(free, run, interval, peak):
    """a (k = 0) at cell 20, b (k = 1) at cell 50, radius 0.1 m; two cells known free: the
    wall lies in the longest run of the others, between its cells' outer edges (cut to
    [1.9, 4.7] m by the radius). Cells 21 and 22 hold -0.4 from the helpers' rays (unknown);
    cells 49 and 51 are b's footprint."""
    m = mapper(robot_radius_m=0.1, trajectory_gap_max_m=0.0)
    a, b = at(20), at(50)
    m.update(a, rssi_k(a, 0))
    free_cells_on_row_10(m, free)
    m.update(b, rssi_k(b, 1))
    lo = m.log_odds[10].astype(np.float64)
    assert int(np.argmax(lo)) in peak
    for c in range(max(run[0], 23), min(run[1], 48) + 1):
        assert lo[c] == pytest.approx(eq6(s_of(c), *interval), rel=1e-4), c
    others = [c for c in range(22, 50) if not run[0] <= c <= run[1] and c not in free]
    assert (lo[others] <= 1e-3).all()  # no wall outside the run (Eq. 6's tail at most)


def test_equal_runs_the_one_nearest_the_middle_wins():
    """As above with cells 23, 31, 39 and 47 known free: three runs of 7 cells, 24..30, 32..38
    and 40..46, centred 2.5, 3.3 and 4.1 m; the interval's middle is (1.9 + 4.7) / 2 = 3.3 m,
    so the wall lies in 32..38: [2.95, 3.65] m, peak at 3.3 m (cell 35) of height
    logit(0.5 + 0.3 * 0.5 / 0.7); the other two runs get nothing."""
    m = mapper(robot_radius_m=0.1, trajectory_gap_max_m=0.0)
    a, b = at(20), at(50)
    m.update(a, rssi_k(a, 0))
    free_cells_on_row_10(m, (23, 31, 39, 47))
    m.update(b, rssi_k(b, 1))
    lo = m.log_odds[10].astype(np.float64)
    assert int(np.argmax(lo)) == 35
    assert lo[35] == pytest.approx(logit(0.5 + 0.3 * 0.5 / 0.7), rel=1e-5)
    for c in range(32, 39):
        assert lo[c] == pytest.approx(eq6(s_of(c), 2.95, 3.65), rel=1e-4), c
    assert (lo[24:31] <= 0).all() and (lo[40:47] <= 0).all()


# -- no room for a wall -------------------------------------------------------------------------
def test_robot_centres_closer_than_two_radii_leave_no_room_for_a_wall():
    """a (k = 0) and b (k = 1) 0.4 m apart with radius 0.25 m: the wall interval
    [s(a) + 0.25, s(b) - 0.25] is empty, the reading is skipped: no cell gains wall evidence.
    0.6 m apart it is [2.05, 2.15] m: L = 0.1 m, so sigma = sigma_min = 0.05 m and the full
    height P = 0.8 at the middle, 2.1 m = cell 23's centre; cells 22 and 24, 0.1 m = 2 sigma
    away, get logit(0.5 + 0.3 exp(-2)) on top of their -0.5 footprint (a's, b's)."""
    for b_col, room in ((24, False), (26, True)):
        m = mapper(robot_radius_m=0.25, footprint_log_odds=-0.5)
        a, b = at(20), at(b_col)
        m.update(a, rssi_k(a, 0))
        before = m.log_odds.astype(np.float64)
        m.update(b, rssi_k(b, 1))
        lo = m.log_odds.astype(np.float64)
        if not room:
            assert (lo <= 0).all()
            assert m.last_gain_by_source["walls"] == 0.0
            # what changed: b's footprint (cells within 0.25 m of b, -0.5) and the piece router
            # .. a (cells 2..19, Delta k = 0: -0.4); nothing else
            xs, ys = GRID.cell_centres()
            want = np.where(np.hypot(xs - b[0], ys - b[1]) <= 0.25, -0.5, 0.0)
            want[10, 2:20] += -0.4
            assert lo - before == pytest.approx(want, abs=1e-6)
            continue
        assert int(np.argmax(lo[10])) == 23
        assert lo[10, 23] == pytest.approx(logit(0.8), rel=1e-5)
        side = logit(0.5 + 0.3 * math.exp(-2.0))
        assert lo[10, 22] == pytest.approx(-0.5 + side, rel=1e-5)
        assert lo[10, 24] == pytest.approx(-0.5 + side, rel=1e-5)
        assert m.last_gain_by_source["walls"] > 0.0


def test_a_piece_whose_cells_are_all_known_free_gets_no_wall():
    """a (k = 0) at cell 20, then b at cell 26 with k = 0 (its ray frees 21..25 with -0.4, its
    0.1 m footprint 25; a's frees 21), again b with k = 0: every cell of 21..25 is now free.
    A third reading at b with k = 1 finds no cell where the wall could be: skipped."""
    m = mapper(robot_radius_m=0.1, trajectory_gap_max_m=0.0, free_log_odds=-0.8)
    a, b = at(20), at(26)
    m.update(a, rssi_k(a, 0))
    m.update(b, rssi_k(b, 0))
    m.update(b, rssi_k(b, 0))
    assert belief_classes(m.occupancy_u8)[0][10, 21:26].all()
    before = m.log_odds.copy()
    m.update(b, rssi_k(b, 1))
    assert m.last_gain_by_source["walls"] == 0.0
    # only the footprint (cell 25 and b's own) and the free piece router .. a change, downwards
    assert (m.log_odds <= before).all()
    assert (m.log_odds[10, 21:25] == before[10, 21:25]).all()


# -- the grid traversal clipped to the grid -----------------------------------------------------
def traverse(x0, y0, x1, y1, shape=(7, 9), size=None):
    n_rows, n_cols = shape
    size = n_rows + n_cols + 2 if size is None else size
    rows, cols = np.empty(size, np.int64), np.empty(size, np.int64)
    t0, t1 = np.empty(size), np.empty(size)
    n = traverse_grid(x0, y0, x1, y1, n_rows, n_cols, rows, cols, t0, t1)
    return list(zip(rows[:n].tolist(), cols[:n].tolist(), strict=True)), t0[:n], t1[:n]


def reference_traversal(x0, y0, x1, y1, shape=(7, 9)):
    """The cells of ``[col, col + 1) x [row, row + 1)`` whose interior the segment passes
    through, with the parameters t at which it enters and leaves them: cut the segment at every
    t where x or y is an integer, and read the cell at the middle of each cut (no traversal)."""
    n_rows, n_cols = shape
    dx, dy = x1 - x0, y1 - y0
    ts = {0.0, 1.0}
    for p0, d, n in ((x0, dx, n_cols), (y0, dy, n_rows)):
        if d != 0.0:
            ts |= {(k - p0) / d for k in range(n + 1) if 0.0 < (k - p0) / d < 1.0}
    ts = sorted(ts)
    out: list[list] = []
    for ta, tb in itertools.pairwise(ts):
        tm = 0.5 * (ta + tb)
        x, y = x0 + tm * dx, y0 + tm * dy
        if 0.0 <= x < n_cols and 0.0 <= y < n_rows:
            cell = (math.floor(y), math.floor(x))
            if out and out[-1][0] == cell and out[-1][2] == ta:
                out[-1][2] = tb
            else:
                out.append([cell, ta, tb])
    return [c for c, _, _ in out], [a for _, a, _ in out], [b for _, _, b in out]


def test_the_traversal_of_segments_from_outside_the_grid_is_clipped_at_every_edge():
    """Random segments with their ends up to 3 cells beyond every edge of a 7 x 9 grid: the
    cells and their entry / exit parameters equal the reference's."""
    rng = np.random.default_rng(53)
    n_inside = 0
    for _ in range(300):
        x0, x1 = rng.uniform(-3.0, 12.0, 2)
        y0, y1 = rng.uniform(-3.0, 10.0, 2)
        cells, t0, t1 = traverse(x0, y0, x1, y1)
        want, w0, w1 = reference_traversal(x0, y0, x1, y1)
        assert cells == want, (x0, y0, x1, y1)
        assert t0 == pytest.approx(w0, abs=1e-9) and t1 == pytest.approx(w1, abs=1e-9)
        n_inside += bool(cells)
    assert n_inside > 150


@pytest.mark.parametrize(
    "segment",
    [
        (-1.0, 0.5, -1.0, 6.5),  # left of the grid, parallel to its edge
        (10.0, 0.5, 10.0, 6.5),  # right
        (0.5, -1.0, 8.5, -1.0),  # below
        (0.5, 8.0, 8.5, 8.0),  # above
        (10.0, 3.5, 14.0, 3.5),  # right, moving away
        (-4.0, 3.5, -1.0, 3.5),  # left, moving towards it
        (4.5, 9.0, 4.5, 12.0),  # above, moving away
        (4.5, -5.0, 4.5, -1.0),  # below, moving towards it
        (-3.0, 2.0, 2.0, -3.0),  # past the corner (0, 0), x + y = -1
        (12.0, 5.0, 7.0, 12.0),  # past the corner (9, 7)
    ],
)
def test_a_segment_that_misses_the_grid_crosses_no_cell(segment):
    assert traverse(*segment)[0] == []
    assert reference_traversal(*segment)[0] == []


def test_a_segment_along_the_grid_s_near_edges_lists_their_cells():
    """x = 0 and y = 0 belong to column 0 and row 0 (cells are [col, col + 1) x [row, row + 1))."""
    assert traverse(0.0, 0.5, 0.0, 3.5)[0] == [(0, 0), (1, 0), (2, 0), (3, 0)]
    assert traverse(4.5, 0.0, 1.5, 0.0)[0] == [(0, 4), (0, 3), (0, 2), (0, 1)]
    assert traverse(0.0, 0.5, 0.0, 3.5)[0] == reference_traversal(0.0, 0.5, 0.0, 3.5)[0]


def test_a_short_buffer_receives_its_length_of_cells_and_nothing_beyond():
    """The traversal stops when the buffer is full (the buffers it is given elsewhere hold any
    traversal): a 3-cell buffer gets the first 3 cells of the full traversal, nothing past it."""
    full = traverse(0.5, 0.5, 8.5, 6.5)[0]
    assert len(full) > 3
    big = [np.full(8, -7, np.int64), np.full(8, -7, np.int64), np.full(8, -7.0), np.full(8, -7.0)]
    n = traverse_grid(0.5, 0.5, 8.5, 6.5, 7, 9, *(b[:3] for b in big))
    assert n == 3
    assert list(zip(big[0][:3].tolist(), big[1][:3].tolist(), strict=True)) == full[:3]
    assert all((b[3:] == -7).all() for b in big)


@pytest.mark.xfail(
    strict=True,
    reason="traverse_grid lists the cell that a segment from outside touches only at its end "
    "point (t0 = t1 = 1), which its docstring says is not listed (clip gives t_lo == t_hi)",
)
def test_a_segment_from_outside_that_ends_on_the_grid_s_edge_lists_no_cell():
    assert reference_traversal(-1.0, 0.5, 0.0, 0.5)[0] == []
    assert traverse(-1.0, 0.5, 0.0, 0.5)[0] == []


# -- more of the mapper's rules -----------------------------------------------------------------
def test_two_walls_go_between_the_first_and_last_cells_not_known_free():
    """a (k = 0) at cell 16, b (k = 2) at cell 50, radius 0.21 m. a's footprint frees cells
    14..18 of row 10; four visits at (c + 0.05, 1.25) free cells 46..49 (0.2 m away; their rays
    leave row 10 before cell 15). The walls lie in [max(1.4 + 0.21, 1.65), min(4.8 - 0.21,
    4.35)] = [1.65, 4.35] m, cut in two halves of 1.35 m with a peak at the middle of each."""
    m = mapper(robot_radius_m=0.21, trajectory_gap_max_m=0.0)
    a, b = at(16), at(50)
    m.update(a, rssi_k(a, 0))
    for c in (46, 47, 48, 49):
        p = (c / 10 + 0.05, 1.25)
        m.update(p, rssi_k(p, 0))
    assert belief_classes(m.occupancy_u8)[0][10, [17, 18, 46, 47, 48, 49]].all()
    m.update(b, rssi_k(b, 2))
    lo = m.log_odds[10].astype(np.float64)
    s_a, sub = 1.65, (4.35 - 1.65) / 2
    sigma, amp = max(S_MIN, S_FRAC * sub), (PEAK - 0.5) * min(1.0, L_REF / sub)
    for c in range(19, 46):
        s = s_of(c)
        centre = s_a + (min(max(math.floor((s - s_a) / sub), 0), 1) + 0.5) * sub
        excess = amp * math.exp(-((s - centre) ** 2) / (2 * sigma**2))
        assert lo[c] == pytest.approx(logit(0.5 + excess) if excess >= 1e-3 else 0.0, rel=1e-4)
    assert int(np.argmax(lo[19:32])) + 19 in (25, 26)  # the first peak, 2.325 m
    assert int(np.argmax(lo[32:46])) + 32 in (38, 39)  # the second, 3.675 m


def test_a_bump_marks_a_contact_cell_in_the_first_column():
    """Robot at x = 0.15 m (column 1), radius 0.05 m, heading west: the contact cell lies
    radius + resolution / 2 = 0.1 m ahead, at x = 0.05 m: column 0, marked with +3."""
    m = mapper(robot_radius_m=0.05)
    m.update((0.15, 1.05), [-100.0], bumped=True, heading_rad=math.pi)
    assert m.log_odds[10, 0] == pytest.approx(3.0)
    assert (m.log_odds[10, 1:] <= 0).all()


def test_the_footprint_at_the_grid_s_far_corner_is_clipped_to_the_grid():
    """Robot at the centre of the last cell (19, 59), radius 0.17 m: the footprint is the cells
    of the grid whose centres lie within 0.17 m: (19, 59), (18, 59), (19, 58), (18, 58)."""
    m = mapper(robot_radius_m=0.17)
    m.update((5.95, 1.95), [-100.0])
    marked = {tuple(c) for c in np.argwhere(m.log_odds != 0).tolist()}
    assert marked == {(19, 59), (18, 59), (19, 58), (18, 58)}
    assert m.log_odds[19, 59] == pytest.approx(-1.0)


def test_small_sum_is_numpy_s_sum_to_the_bit():
    """kmeans1d's compiled sums equal numpy's pairwise summation bit for bit (numpy is the
    reference, not the code under test), for every length that takes another path."""
    from sfw_gym.mapping.kmeans1d import _pairwise_sum, _small_sum

    rng = np.random.default_rng(5)
    for n in [*range(1, 40), 64, 127, 128, 129, 300, 1031]:
        a = rng.normal(0.0, 1e3, n) * 10.0 ** rng.integers(-8, 8, n)
        if n <= 128:
            assert _small_sum(a) == a.sum(), n
        assert _pairwise_sum(a) == a.sum(), n


def test_dry_run_messages_name_the_method():
    from sfw_gym.core.errors import ConfigError
    from sfw_gym.mapping.dry_run import DryRun

    dry = DryRun.of_mapper(mapper())
    with pytest.raises(
        ConfigError, match=r"^DryRun\.path_gains: every position must lie inside the grid$"
    ):
        dry.path_gains(np.array([(99.0, 1.0)]), [0], [0])
