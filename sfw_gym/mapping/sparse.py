"""Sparse inverse k-visibility (Alg. 2 of Kim et al., arXiv 2408.07757) in Bayesian log-odds form.

Each :meth:`SparseInverseKVisibility.update` takes the robot's position and one RSSI reading per
router and, in one compiled kernel:

1. estimates every heard router's k-value (:mod:`sfw_gym.mapping.k_estimation`);
2. rule 1: marks the footprint (cells whose centre lies within ``robot_radius_m``) free; a bump
   marks the contact cell, ``robot_radius_m + resolution_m / 2`` ahead along ``heading_rad``,
   occupied;
3. for the selected router(s) (``"strongest"`` raw RSSI, or ``"all"``), traverses the ray
   router -> robot and cuts it at the earlier trajectory points on it (a per-router raster of
   visited cells storing their filtered feature; their k is re-read with the *current*
   thresholds). The router is an anchor with k = 0. With ``extend_past_robot``, the ray also
   continues past the robot to the grid's edge and is cut at every earlier trajectory point
   beyond it too (rule 4 holds along the whole line from the router: two points on it with the
   same k bound free space wherever they lie, so later readings also clear the stretches
   between earlier passes);
4. updates every piece between consecutive anchors by its Delta k:

   - Delta k = 0 (rules 2, 4): every cell strictly inside the piece gets ``free_log_odds``;
   - Delta k = 1 (rule 3, Eq. 6): the wall lies in the piece shortened by ``robot_radius_m`` at
     each end that is a trajectory point (a robot centre keeps that far from walls; the router
     end is not shortened); with ``L`` that length and ``s`` the arc position from its start,
     a cell gets ``logit(P(s))``,
     ``P(s) = 0.5 + (p_peak - 0.5) * min(1, L_ref / L) * exp(-(s - L/2)^2 / (2 sigma^2))``,
     ``sigma = max(sigma_min, sigma_fraction * L)``: a peak at the midpoint that lowers and
     widens as the piece grows; cells where the excess is below 1e-3 are skipped. The interval
     is also narrowed to where the wall can be: the longest run of cells not yet classified
     free (a wall is one contiguous stretch), so the estimate sharpens as the map fills in;
     One piece lifts a cell to at most ``wall_cap_factor * logit(P(s))``: successive readings
     along one ray are far from independent, and summing many flat, long-piece likelihoods
     would otherwise build confident walls out of weak evidence;
   - Delta k = m > 1: the piece (trimmed of the cells classified free at its ends) is cut into
     m equal sub-pieces, each updated as Delta k = 1 (m peaks at the sub-piece midpoints);
   - Delta k < 0, or Delta k > 0 on a piece with no room for a wall (robot centres closer than
     ``2 * robot_radius_m``, or every cell known free): inconsistent, skipped;
   - both ends at ``k = max_k``: the estimator's K means "K or more walls", so equal readings
     there do not mean no wall between them: skipped;

5. fuses by adding log-odds (Eq. 7), clamped to ``[log_odds_min, log_odds_max]``, and keeps the
   map entropy, the uint8 map and the cell classes up to date for the touched cells only.
   It counts the update's bits by where they came from (:data:`GAIN_SOURCES`).

The first reading of an update never serves as its own anchor: the trajectory raster is written
after the rays (the segment from the previous position, if closer than
``trajectory_gap_max_m``, and the current cell).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from sfw_gym.core.constants import U8_UNKNOWN
from sfw_gym.core.errors import ConfigError
from sfw_gym.mapping.config import MapperConfig
from sfw_gym.mapping.grid import CLASS_FREE, CLASS_UNKNOWN, GridSpec, u8_class
from sfw_gym.mapping.k_estimation import (
    KERNEL_ARG_N_THR,
    KERNEL_ARG_THRESHOLDS,
    KEstimator,
    add_samples,
    k_from_thresholds,
)
from sfw_gym.mapping.raycast import ray_buffer_size, traverse_grid

_LN2 = math.log(2.0)
# Indices into the float64 `state` array of the kernel.
_S_ENTROPY, _S_UID, _S_PREV_X, _S_PREV_Y, _S_HAS_PREV, _S_N_TOUCHED, _S_N_CHANGED = range(7)
#: Where an update's bits came from (:attr:`SparseInverseKVisibility.last_gain_by_source`):
#: the footprint (rule 1); the ray's Delta k = 0 pieces in sight of the router (k = 0 at both
#: ends); its Delta k = 0 pieces behind walls (equal k > 0); its pieces past the robot (the
#: extension, any Delta k); wall evidence (Delta k > 0 pieces between router and robot, bumps).
GAIN_SOURCES = ("footprint", "line_of_sight", "out_of_sight", "past_robot", "walls")
_SRC_FOOT, _SRC_LOS, _SRC_OOS, _SRC_PAST, _SRC_WALL = range(7, 12)
_N_STATE = 12
# Indices into the float64 `params` array of the kernel.
(
    _P_RES,
    _P_RADIUS,
    _P_FREE,
    _P_FOOT,
    _P_BUMP,
    _P_PEAK,
    _P_LREF,
    _P_SFRAC,
    _P_SMIN,
    _P_LMIN,
    _P_LMAX,
    _P_GAP,
    _P_CAP,
) = range(13)
# Cell classes kept in `cls`.


@njit(cache=True)
def cell_entropy_bits(lo):
    """Binary entropy (bits) of a cell with log-odds ``lo``."""
    a = abs(lo)
    e = np.exp(-a)
    return (np.log1p(e) + a * e / (1.0 + e)) / _LN2


@njit(cache=True)
def log_odds_to_u8(lo):
    """``floor(255 * P(free))``: 0 wall ... 255 free, 127 at log-odds 0."""
    e = np.exp(-abs(lo))
    p_free = e / (1.0 + e) if lo >= 0.0 else 1.0 / (1.0 + e)
    return min(int(255.0 * p_free), 255)


@njit(cache=True)
def _apply(cell, delta, cap, lmin, maps, track):
    """Add ``delta`` to one cell's log-odds; returns the entropy decrease (bits).

    The result is clamped below at ``lmin``; a positive ``delta`` never lifts the cell above
    ``cap`` (nor lowers one already above it). Keeps the cell's entropy and uint8 value current
    and records the cell (with its class before this update) the first time it is touched.
    """
    lo, ent, u8, cls, _, inside, stamp = maps
    touched, old_cls, _, state = track
    if not inside[cell]:
        return 0.0
    old = lo[cell]
    if delta > 0.0:
        new = np.float32(min(old + delta, max(old, cap)))
    else:
        new = np.float32(max(old + delta, lmin))
    if new == old:
        return 0.0
    uid = np.int64(state[_S_UID])
    if stamp[cell] != uid:
        n = np.int64(state[_S_N_TOUCHED])
        stamp[cell] = uid
        touched[n] = cell
        old_cls[n] = cls[cell]
        state[_S_N_TOUCHED] = n + 1
    lo[cell] = new
    a = abs(np.float64(new))
    e = np.exp(-a)
    h = (np.log1p(e) + a * e / (1.0 + e)) / _LN2
    gain = ent[cell] - h
    ent[cell] = h
    p_free = e / (1.0 + e) if new >= 0.0 else 1.0 / (1.0 + e)
    u8[cell] = min(int(255.0 * p_free), 255)
    return gain


@njit(cache=True)
def _wall_piece(s_a, s_b, dk, j0, j1, ray, l_tot, n_cols, params, maps, track):
    """Eq. 6 over ray cells ``j0..j1-1`` for an interval ``[s_a, s_b]`` holding ``dk`` walls."""
    rows, cols, t0, t1 = ray
    lo = maps[0]
    res = params[_P_RES]
    sub = (s_b - s_a) / dk
    sigma = max(params[_P_SMIN] / res, params[_P_SFRAC] * sub)
    amp = (params[_P_PEAK] - 0.5) * min(1.0, params[_P_LREF] / (sub * res))
    inv2s2 = 1.0 / (2.0 * sigma * sigma)
    lmin = params[_P_LMIN]
    lmax = params[_P_LMAX]
    cap_factor = params[_P_CAP]
    gain = 0.0
    for j in range(j0, j1):
        s = 0.5 * (t0[j] + t1[j]) * l_tot
        q = min(max(int(np.floor((s - s_a) / sub)), 0), dk - 1)
        c = s_a + (q + 0.5) * sub
        x = amp * np.exp(-(s - c) * (s - c) * inv2s2)
        if x < 1e-3:
            continue
        p = 0.5 + x
        delta = np.log(p / (1.0 - p))
        cap = min(lmax, cap_factor * delta)
        cell = rows[j] * n_cols + cols[j]
        if lo[cell] < cap:
            gain += _apply(cell, delta, cap, lmin, maps, track)
    return gain


@njit(cache=True)
def _wall_candidates(j0, j1, dk, s_mid, ray, l_tot, cls, n_cols):
    """Ray cells ``[j_lo, j_hi)`` where the walls of a piece can be (not known free).

    One wall (``dk == 1``): the longest run of cells not classified free (ties: the run nearest
    the piece's middle), since a wall is one contiguous stretch. Several walls: everything
    between the first and the last cell not classified free. Empty if all cells are free.
    """
    rows, cols, t0, t1 = ray
    if dk > 1:
        j_lo = j0
        while j_lo < j1 and cls[rows[j_lo] * n_cols + cols[j_lo]] == CLASS_FREE:
            j_lo += 1
        j_hi = j1
        while j_hi > j_lo and cls[rows[j_hi - 1] * n_cols + cols[j_hi - 1]] == CLASS_FREE:
            j_hi -= 1
        return j_lo, j_hi
    best_lo = j0
    best_hi = j0
    best_off = np.inf
    j = j0
    while j < j1:
        if cls[rows[j] * n_cols + cols[j]] == CLASS_FREE:
            j += 1
            continue
        start = j
        while j < j1 and cls[rows[j] * n_cols + cols[j]] != CLASS_FREE:
            j += 1
        off = abs(0.5 * (t0[start] + t1[j - 1]) * l_tot - s_mid)
        if j - start > best_hi - best_lo or (j - start == best_hi - best_lo and off < best_off):
            best_lo = start
            best_hi = j
            best_off = off
    return best_lo, best_hi


@njit(cache=True)
def _push_anchors(traj, ray, l_tot, lo, hi, anchors, n_anc):
    """Append the visited ray cells lo..hi-1 (trajectory points) as anchors with their k.

    ``traj`` is one router's trajectory raster, its k thresholds and their count."""
    raster_r, thresholds_r, n_thr_r = traj
    rows, cols, t0, t1 = ray
    anc_j, anc_s, anc_k = anchors
    for j in range(lo, hi):
        f = raster_r[rows[j], cols[j]]
        if f == f:  # visited (not NaN)
            anc_j[n_anc] = j
            anc_s[n_anc] = 0.5 * (t0[j] + t1[j]) * l_tot
            anc_k[n_anc] = k_from_thresholds(f, thresholds_r, n_thr_r)
            n_anc += 1
    return n_anc


@njit(cache=True)
def _ray_update(k_robot, gx, gy, router_g, extend, params, traj, maps, track, ray, anchors):
    """Segment the ray from the router at ``router_g`` at earlier trajectory points (``traj``:
    that router's, as :func:`_push_anchors` reads it) and update every piece."""
    rows, cols, t0, t1 = ray
    anc_j, anc_s, anc_k = anchors
    lo = maps[0]
    cls = maps[3]
    n_rows, n_cols = traj[0].shape
    rgx = router_g[0]
    rgy = router_g[1]
    dx = gx - rgx
    dy = gy - rgy
    dist = np.sqrt(dx * dx + dy * dy)
    if dist < 1e-9:
        return 0.0
    ex, ey = gx, gy
    if extend:
        ext = (n_rows + n_cols + 2.0) / dist
        ex = gx + dx * ext
        ey = gy + dy * ext
    n = traverse_grid(rgx, rgy, ex, ey, n_rows, n_cols, rows, cols, t0, t1)
    if n == 0:
        return 0.0
    l_tot = np.sqrt((ex - rgx) ** 2 + (ey - rgy) ** 2)
    t_robot = dist / l_tot
    # The robot's cell on the ray: the first whose exit parameter reaches the robot.
    i_r = n - 1
    for j in range(n):
        if t1[j] >= t_robot:
            i_r = j
            break
    # Anchors: router (k = 0), earlier trajectory cells, robot, first trajectory cell beyond.
    anc_j[0] = -1
    anc_s[0] = 0.0
    anc_k[0] = 0
    n_anc = 1
    n_anc = _push_anchors(traj, ray, l_tot, 0, i_r, anchors, n_anc)
    anc_j[n_anc] = i_r
    anc_s[n_anc] = dist
    anc_k[n_anc] = k_robot
    a_robot = n_anc  # the robot's anchor: the pieces from it on are the extension
    n_anc += 1
    if extend:
        n_anc = _push_anchors(traj, ray, l_tot, i_r + 1, n, anchors, n_anc)
    rad = params[_P_RADIUS] / params[_P_RES]
    lmin = params[_P_LMIN]
    lmax = params[_P_LMAX]
    free = params[_P_FREE]
    k_sat = traj[1].shape[0]
    state = track[3]
    gain = 0.0
    for a in range(n_anc - 1):
        j0 = anc_j[a] + 1
        j1 = anc_j[a + 1]
        if j1 <= j0:
            continue
        dk = anc_k[a + 1] - anc_k[a]
        if anc_k[a] >= k_sat and anc_k[a + 1] >= k_sat:
            continue  # both ends read "K or more": the walls between them are unknown
        piece = 0.0
        if dk == 0:
            for j in range(j0, j1):
                cell = rows[j] * n_cols + cols[j]
                if lo[cell] > lmin:  # cheap skip of saturated cells (most of them)
                    piece += _apply(cell, free, lmax, lmin, maps, track)
        elif dk > 0:
            # A wall keeps a robot radius from every trajectory point (the router is none)
            # and lies where the map does not already know free space.
            s_a = anc_s[a] + (rad if a > 0 else 0.0)
            s_b = anc_s[a + 1] - rad
            j_lo, j_hi = _wall_candidates(j0, j1, dk, 0.5 * (s_a + s_b), ray, l_tot, cls, n_cols)
            if j_hi == j_lo:
                continue
            s_a = max(s_a, t0[j_lo] * l_tot)
            s_b = min(s_b, t1[j_hi - 1] * l_tot)
            if s_b - s_a <= 1e-9:
                continue
            piece = _wall_piece(s_a, s_b, dk, j0, j1, ray, l_tot, n_cols, params, maps, track)
        if a >= a_robot:
            state[_SRC_PAST] += piece
        elif dk > 0:
            state[_SRC_WALL] += piece
        elif anc_k[a] == 0:
            state[_SRC_LOS] += piece
        else:
            state[_SRC_OOS] += piece
        gain += piece
    return gain


@njit(cache=True)
def _footprint_update(gx, gy, bumped, heading, params, maps, track, n_rows, n_cols):
    """Rule 1: the footprint free; a bump marks the contact cell ahead occupied. Returns the
    bits gained (and adds them to the update's sources)."""
    lo = maps[0]
    state = track[3]
    res = params[_P_RES]
    lmin = params[_P_LMIN]
    lmax = params[_P_LMAX]
    rad = params[_P_RADIUS] / res
    rc = int(np.floor(gx))
    rr = int(np.floor(gy))
    r_lo = max(int(np.floor(gy - rad)) - 1, 0)
    r_hi = min(int(np.floor(gy + rad)) + 1, n_rows - 1)
    c_lo = max(int(np.floor(gx - rad)) - 1, 0)
    c_hi = min(int(np.floor(gx + rad)) + 1, n_cols - 1)
    foot = params[_P_FOOT]
    gain = 0.0
    for i in range(r_lo, r_hi + 1):
        for j in range(c_lo, c_hi + 1):
            ddx = j + 0.5 - gx
            ddy = i + 0.5 - gy
            if (ddx * ddx + ddy * ddy <= rad * rad or (i == rr and j == rc)) and lo[
                i * n_cols + j
            ] > lmin:
                gain += _apply(i * n_cols + j, foot, lmax, lmin, maps, track)
    state[_SRC_FOOT] += gain
    if bumped and heading == heading:
        reach = rad + 0.5
        bc = int(np.floor(gx + reach * np.cos(heading)))
        br = int(np.floor(gy + reach * np.sin(heading)))
        if 0 <= br < n_rows and 0 <= bc < n_cols and not (br == rr and bc == rc):
            bump = _apply(br * n_cols + bc, params[_P_BUMP], lmax, lmin, maps, track)
            state[_SRC_WALL] += bump
            gain += bump
    return gain


@njit(cache=True)
def _begin_update(state):
    """A new update: a new stamp, nothing touched, no bits from any source yet."""
    state[_S_UID] += 1.0
    state[_S_N_TOUCHED] = 0.0
    state[_S_N_CHANGED] = 0.0
    for i in range(_SRC_FOOT, _N_STATE):
        state[i] = 0.0


@njit(cache=True)
def _trajectory_cells(gx, gy, params, state, ray, n_rows, n_cols):
    """The raster cells this reading marks: the segment from the previous position (if
    closer than ``trajectory_gap_max_m``, in ``ray[0:2][:n]``; returns ``n``) and the current
    cell (the caller's); moves the previous position here."""
    rows, cols, t0, t1 = ray
    n_traj = 0
    if state[_S_HAS_PREV] > 0.0:
        px = state[_S_PREV_X]
        py = state[_S_PREV_Y]
        if params[_P_RES] * np.sqrt((gx - px) ** 2 + (gy - py) ** 2) <= params[_P_GAP]:
            n_traj = traverse_grid(px, py, gx, gy, n_rows, n_cols, rows, cols, t0, t1)
    state[_S_PREV_X] = gx
    state[_S_PREV_Y] = gy
    state[_S_HAS_PREV] = 1.0
    return n_traj


@njit(cache=True)
def _classify_touched(maps, track):
    """The classes of the touched cells; records those whose class changed."""
    _, _, u8, cls, classified, _, _ = maps
    touched, old_cls, changed, state = track
    n_c = 0
    for i in range(np.int64(state[_S_N_TOUCHED])):
        cell = touched[i]
        c = u8_class(u8[cell])
        cls[cell] = c
        classified[cell] = c != CLASS_UNKNOWN
        if c != old_cls[i]:
            changed[n_c] = cell
            n_c += 1
    state[_S_N_CHANGED] = n_c


@njit(cache=True)
def _update_kernel(
    gx,
    gy,
    rssi,
    bumped,
    heading,
    routers_g,
    policy_all,
    extend,
    params,
    kest,
    feature,
    k_out,
    selected,
    dist_buf,
    raster,
    maps,
    track,
    ray,
    anchors,
):
    """One full update; returns ``(gain_bits, refit_due)``, or ``(nan, False)`` untouched if an
    RSSI value is not finite."""
    for r in range(rssi.shape[0]):
        if not np.isfinite(rssi[r]):
            return np.nan, False
    thresholds = kest[KERNEL_ARG_THRESHOLDS]
    n_thr = kest[KERNEL_ARG_N_THR]
    state = track[3]
    rows, cols = ray[0], ray[1]
    n_rows = raster.shape[1]
    n_cols = raster.shape[2]
    n_r = rssi.shape[0]
    res = params[_P_RES]
    _begin_update(state)
    for r in range(n_r):
        dist_buf[r] = res * np.sqrt((gx - routers_g[r, 0]) ** 2 + (gy - routers_g[r, 1]) ** 2)
    due = add_samples(rssi, dist_buf, *kest, feature, k_out)
    gain = _footprint_update(gx, gy, bumped, heading, params, maps, track, n_rows, n_cols)
    # Router selection: the strongest raw RSSI (the paper), or every heard router.
    n_sel = 0
    if policy_all:
        for r in range(n_r):
            if k_out[r] >= 0:
                selected[n_sel] = r
                n_sel += 1
    else:
        best = -1
        for r in range(n_r):
            if k_out[r] >= 0 and (best < 0 or rssi[r] > rssi[best]):
                best = r
        if best >= 0:
            selected[0] = best
            n_sel = 1
    for q in range(n_sel):
        r = selected[q]
        traj = (raster[r], thresholds[r], n_thr[r])
        gain += _ray_update(
            k_out[r], gx, gy, routers_g[r], extend, params, traj, maps, track, ray, anchors
        )
    # Trajectory raster (after the rays, so this reading is not its own anchor).
    n_traj = _trajectory_cells(gx, gy, params, state, ray, n_rows, n_cols)
    rr = int(np.floor(gy))
    rc = int(np.floor(gx))
    for r in range(n_r):
        if k_out[r] < 0:
            continue
        f = np.float32(feature[r])
        for j in range(n_traj):
            raster[r, rows[j], cols[j]] = f
        raster[r, rr, rc] = f
    _classify_touched(maps, track)
    state[_S_ENTROPY] -= gain
    return gain, due


def kernel_params(grid: GridSpec, cfg: MapperConfig) -> np.ndarray:
    """The kernel's float64 parameter array (indices ``_P_*``)."""
    return np.array(
        [
            grid.resolution_m,
            cfg.robot_radius_m,
            cfg.free_log_odds,
            cfg.footprint_log_odds,
            cfg.bump_log_odds,
            cfg.wall_peak_probability,
            cfg.wall_ref_length_m,
            cfg.wall_sigma_fraction,
            cfg.wall_sigma_min_m,
            cfg.log_odds_min,
            cfg.log_odds_max,
            cfg.trajectory_gap_max_m,
            cfg.wall_cap_factor,
        ],
        dtype=np.float64,
    )


def inside_mask(grid: GridSpec, cfg: MapperConfig) -> np.ndarray:
    """Flat bool per cell: inside ``outer_bounds_m`` (every cell without bounds)."""
    inside = np.ones(grid.shape[0] * grid.shape[1], np.bool_)
    if cfg.outer_bounds_m is not None:
        xs, ys = grid.cell_centres()
        xmin, ymin, xmax, ymax = cfg.outer_bounds_m
        inside[:] = ((xs >= xmin) & (xs <= xmax) & (ys >= ymin) & (ys <= ymax)).ravel()
    return inside


def touched_capacity(grid: GridSpec, cfg: MapperConfig, n_routers: int) -> int:
    """The most cells one update can touch: the footprint's box, a bump, every router's ray."""
    rad_cells = math.ceil(cfg.robot_radius_m / grid.resolution_m) + 2
    return (2 * rad_cells + 1) ** 2 + 2 + n_routers * ray_buffer_size(grid.shape)


def _read_only_view(a: np.ndarray) -> np.ndarray:
    """A read-only view of ``a``."""
    view = a.view()
    view.flags.writeable = False
    return view


def kernel_buffers(
    grid: GridSpec, cfg: MapperConfig, n_routers: int, state: np.ndarray
) -> tuple[tuple, tuple, tuple]:
    """The kernel's scratch: the touched-cell tracking (around ``state``), the ray's cells and
    the anchors' buffers."""
    cap = touched_capacity(grid, cfg, n_routers)
    n = ray_buffer_size(grid.shape)
    track = (np.empty(cap, np.int64), np.empty(cap, np.int8), np.empty(cap, np.int64), state)
    ray = (np.empty(n, np.int64), np.empty(n, np.int64), np.empty(n), np.empty(n))
    anchors = (np.empty(n + 2, np.int64), np.empty(n + 2), np.empty(n + 2, np.int64))
    return track, ray, anchors


@dataclass(frozen=True)
class MapperState:
    """What the mapper keeps besides its log-odds, as read-only views
    (:meth:`SparseInverseKVisibility.state`): enough to run its update dry
    (:class:`~sfw_gym.mapping.dry_run.DryRun`). The robot's own, never the ground truth.

    Attributes:
        config: The mapper's configuration.
        trajectory_features: ``(R, H, W)`` float32, per router the filtered RSSI feature of the
            last reading taken in each cell (NaN where the trajectory never passed).
        k_thresholds: ``(R, max_k)`` the k-estimator's thresholds per router (the first
            ``n_thresholds[r]`` in use).
        n_thresholds: ``(R,)`` how many thresholds each router uses.
        cell_entropy_bits: ``(H, W)`` float64, each cell's entropy as the mapper keeps it.
        previous_xy: Where the last reading was taken (world metres), None before the first.
    """

    config: MapperConfig
    trajectory_features: np.ndarray
    k_thresholds: np.ndarray
    n_thresholds: np.ndarray
    cell_entropy_bits: np.ndarray
    previous_xy: tuple[float, float] | None


class SparseInverseKVisibility:
    """Online occupancy map from positions and RSSI: sparse inverse k-visibility (Alg. 2).

    See the module docstring for the algorithm. The map starts unknown (log-odds 0,
    P(occupied) = 0.5, 1 bit per cell).

    Args:
        grid: Map geometry.
        routers_xy: ``(R, 2)`` router positions in world metres (may lie outside the grid).
        config: Mapper configuration.

    Raises:
        ConfigError: On a malformed grid, router array or config.
    """

    def __init__(self, grid: GridSpec, routers_xy, config: MapperConfig | None = None) -> None:
        if not isinstance(grid, GridSpec):
            raise ConfigError(f"grid must be a GridSpec, got {type(grid).__name__}")
        cfg = config if config is not None else MapperConfig()
        if not isinstance(cfg, MapperConfig):
            raise ConfigError(f"config must be a MapperConfig, got {type(cfg).__name__}")
        routers = np.asarray(routers_xy, dtype=np.float64)
        if routers.ndim != 2 or routers.shape[1] != 2 or routers.shape[0] < 1:
            raise ConfigError(f"routers_xy must have shape (R, 2) with R >= 1, got {routers.shape}")
        if not np.isfinite(routers).all():
            raise ConfigError(f"routers_xy must be finite, got {routers.tolist()}")
        self.grid = grid
        self.config = cfg
        self.routers_xy = routers.copy()
        self.routers_xy.flags.writeable = False
        self.n_routers = n_r = routers.shape[0]
        self._routers_g = grid.world_to_grid(routers)
        self._params = kernel_params(grid, cfg)
        self._policy_all = cfg.router_policy == "all"
        self._k_estimator = KEstimator(n_r, cfg)
        self._kest = self._k_estimator._kernel_args()
        h, w = grid.shape
        n_cells = h * w
        inside = inside_mask(grid, cfg)
        self._lo = np.zeros(n_cells, np.float32)
        self._ent = np.ones(n_cells, np.float64)
        self._u8 = np.full(n_cells, U8_UNKNOWN, np.uint8)
        self._cls = np.zeros(n_cells, np.int8)
        self._classified = np.zeros(n_cells, np.bool_)
        self._inside = inside
        self._stamp = np.zeros(n_cells, np.int64)
        self._maps = (
            self._lo,
            self._ent,
            self._u8,
            self._cls,
            self._classified,
            inside,
            self._stamp,
        )
        self._state = np.zeros(_N_STATE, np.float64)
        self._track, self._ray, self._anchors = kernel_buffers(grid, cfg, n_r, self._state)
        self._changed = self._track[2]
        self._raster = np.full((n_r, h, w), np.nan, np.float32)
        self._selected = np.zeros(n_r, np.int64)
        self._dist = np.empty(n_r, np.float64)
        self._make_views()
        self.reset()

    def reset(self) -> None:
        """Forget the map, the trajectory and the k-estimator (in place: views stay valid)."""
        self._lo.fill(0.0)
        self._ent.fill(1.0)
        self._u8.fill(U8_UNKNOWN)
        self._cls.fill(CLASS_UNKNOWN)
        self._classified.fill(False)
        self._raster.fill(np.nan)
        self._stamp.fill(0)
        self._state.fill(0.0)
        self._state[_S_ENTROPY] = float(self._inside.sum())
        self._k_estimator.reset()
        self.n_updates = 0

    _VIEWS = ("_lo_view", "_u8_view", "_classified_view", "_state_views")

    def _make_views(self) -> None:
        """The read-only views the properties and :meth:`state` hand out (made once: the arrays
        they show change in place)."""
        shape = self.grid.shape
        self._lo_view = _read_only_view(self._lo.reshape(shape))
        self._u8_view = _read_only_view(self._u8.reshape(shape))
        self._classified_view = _read_only_view(self._classified.reshape(shape))
        kest = self._kest
        self._state_views = (
            _read_only_view(self._raster),
            _read_only_view(kest[KERNEL_ARG_THRESHOLDS]),
            _read_only_view(kest[KERNEL_ARG_N_THR]),
            _read_only_view(self._ent.reshape(shape)),
        )

    def __getstate__(self) -> dict:
        # Views would unpickle as copies, cut off from the arrays they show: rebuild them.
        state = self.__dict__.copy()
        for name in self._VIEWS:
            del state[name]
        return state

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)
        self._make_views()

    def update(
        self,
        position_xy,
        rssi_dbm,
        bumped: bool = False,
        heading_rad: float | None = None,
    ) -> float:
        """Fuse one reading taken at ``position_xy``.

        Args:
            position_xy: Robot ``(x, y)`` in world metres (must lie inside the grid).
            rssi_dbm: ``(R,)`` RSSI per router in dBm; <= -100 means "not heard" (skipped).
            bumped: Whether the bumper fired at this position.
            heading_rad: Direction of the contact when bumped (world frame, radians from +x).
                Without it a bump marks no wall (the footprint is still free).

        Returns:
            Information gain of this update: the decrease of the map entropy, in bits.

        Raises:
            ConfigError: On a non-finite or outside-the-grid position, a non-finite RSSI, a
                wrong vector length or a non-finite heading. The map is left untouched.
        """
        try:
            n_pos = len(position_xy)
            x = float(position_xy[0])
            y = float(position_xy[1])
        except (TypeError, ValueError, IndexError) as exc:
            raise ConfigError(f"position_xy must be (x, y), got {position_xy!r}") from exc
        if n_pos != 2 or not (math.isfinite(x) and math.isfinite(y)):
            raise ConfigError(f"position_xy must be two finite numbers, got {position_xy!r}")
        grid = self.grid
        gx = (x - grid.origin_xy[0]) / grid.resolution_m
        gy = (y - grid.origin_xy[1]) / grid.resolution_m
        if not (0.0 <= gx < grid.shape[1] and 0.0 <= gy < grid.shape[0]):
            raise ConfigError(f"position_xy {position_xy!r} lies outside the grid {grid.bounds}")
        rssi = rssi_dbm
        if type(rssi) is not np.ndarray or rssi.dtype != np.float64:
            try:
                rssi = np.asarray(rssi_dbm, dtype=np.float64)
            except (TypeError, ValueError) as exc:
                raise ConfigError(f"rssi_dbm must be numbers, got {rssi_dbm!r}") from exc
        if rssi.shape != (self.n_routers,):
            raise ConfigError(f"rssi_dbm must have shape ({self.n_routers},), got {rssi.shape}")
        if heading_rad is None:
            heading = math.nan
        else:
            heading = float(heading_rad)
            if not math.isfinite(heading):
                raise ConfigError(f"heading_rad must be finite or None, got {heading_rad!r}")
        ke = self._k_estimator
        gain, due = _update_kernel(
            gx,
            gy,
            rssi,
            bool(bumped),
            heading,
            self._routers_g,
            self._policy_all,
            self.config.extend_past_robot,
            self._params,
            self._kest,
            ke._feature,
            ke._k,
            self._selected,
            self._dist,
            self._raster,
            self._maps,
            self._track,
            self._ray,
            self._anchors,
        )
        if gain != gain:
            raise ConfigError(
                f"rssi_dbm must be finite (use -100 dBm for 'not heard'), got {rssi.tolist()}"
            )
        if due:
            ke.refit()
        self.n_updates += 1
        return gain

    # -- read-only views and summaries ------------------------------------------------------
    @property
    def log_odds(self) -> np.ndarray:
        """Log-odds of "occupied" per cell, float32 ``(n_rows, n_cols)``, read-only view."""
        return self._lo_view

    @property
    def occupancy_u8(self) -> np.ndarray:
        """uint8 map ``floor(255 * P(free))``: 0 wall ... 255 free, 127 unknown. Read-only view."""
        return self._u8_view

    @property
    def probability(self) -> np.ndarray:
        """P(occupied) per cell, float32 ``(n_rows, n_cols)`` (a new array)."""
        return (1.0 / (1.0 + np.exp(-self._lo_view.astype(np.float64)))).astype(np.float32)

    @property
    def classified(self) -> np.ndarray:
        """Cells known free or wall (``occupancy_u8`` in the free or wall third). Read-only view."""
        return self._classified_view

    @property
    def entropy_bits(self) -> float:
        """Total map entropy in bits (cells outside ``outer_bounds_m`` excluded)."""
        return float(self._state[_S_ENTROPY])

    def state(self) -> MapperState:
        """The mapper's state besides its log-odds, as read-only views (:class:`MapperState`)."""
        st = self._state
        previous = None
        if st[_S_HAS_PREV] > 0.0:
            res, (x0, y0) = self.grid.resolution_m, self.grid.origin_xy
            previous = (x0 + st[_S_PREV_X] * res, y0 + st[_S_PREV_Y] * res)
        raster, thresholds, n_thresholds, entropy = self._state_views
        return MapperState(
            config=self.config,
            trajectory_features=raster,
            k_thresholds=thresholds,
            n_thresholds=n_thresholds,
            cell_entropy_bits=entropy,
            previous_xy=previous,
        )

    @property
    def last_gain_by_source(self) -> dict[str, float]:
        """The last update's bits by where they came from (:data:`GAIN_SOURCES`); they sum to
        its gain."""
        bits = self._state[_SRC_FOOT:_N_STATE].tolist()
        return dict(zip(GAIN_SOURCES, bits, strict=True))

    @property
    def last_changed_cells(self) -> np.ndarray:
        """Flat indices of cells whose class (free/unknown/wall) changed in the last update."""
        return self._changed[: int(self._state[_S_N_CHANGED])].copy()

    @property
    def last_k(self) -> np.ndarray:
        """k-values estimated at the last update, ``(R,)`` int, -1 where not heard."""
        return self._k_estimator.last_k

    @property
    def last_routers(self) -> np.ndarray:
        """Indices of the routers whose rays the last update used."""
        k = self._k_estimator._k
        if self.config.router_policy == "all":
            return np.flatnonzero(k >= 0)
        return self._selected[:1].copy() if (k >= 0).any() else np.empty(0, np.int64)

    @property
    def k_estimator(self) -> KEstimator:
        """The RSSI -> k estimator (its thresholds, sample counts)."""
        return self._k_estimator

    def recompute_entropy_bits(self) -> float:
        """Entropy recomputed from the whole map (for checks; O(cells))."""
        a = np.abs(self._lo.astype(np.float64))[self._inside]
        e = np.exp(-a)
        return float(((np.log1p(e) + a * e / (1.0 + e)) / _LN2).sum())
