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
   continues past the robot to the first earlier trajectory point beyond it;
4. updates every piece between consecutive anchors by its Delta k:

   - Delta k = 0 (rules 2, 4): every cell strictly inside the piece gets ``free_log_odds``;
   - Delta k = 1 (rule 3, Eq. 6): cell at arc position ``s`` gets ``logit(P(s))`` with
     ``P(s) = 0.5 + (p_peak - 0.5) * min(1, L_ref / L) * exp(-(s - L/2)^2 / (2 sigma^2))``,
     ``sigma = max(sigma_min, sigma_fraction * L)``, ``L`` the piece length: a peak at the midpoint
     that lowers and widens as the piece grows; cells where the excess is below 1e-3 are skipped;
   - Delta k = m > 1: the piece is cut into m equal sub-pieces, each updated as Delta k = 1
     (m peaks at the sub-piece midpoints);
   - Delta k < 0, or Delta k > 0 on a piece shorter than ``2 * robot_radius_m`` between two
     trajectory points (two robot centres cannot have a wall between them closer than that):
     inconsistent, skipped;

5. fuses by adding log-odds (Eq. 7), clamped to ``[log_odds_min, log_odds_max]``, and keeps the
   map entropy, the uint8 map and the cell classes up to date for the touched cells only.

The first reading of an update never serves as its own anchor: the trajectory raster is written
after the rays (the segment from the previous position, if closer than
``trajectory_gap_max_m``, and the current cell).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from sfw_gym.errors import ConfigError
from sfw_gym.mapping.config import MapperConfig
from sfw_gym.mapping.grid import U8_FREE_MIN, U8_UNKNOWN, U8_WALL_MAX, GridSpec
from sfw_gym.mapping.k_estimation import KEstimator, add_samples, k_from_thresholds
from sfw_gym.mapping.raycast import ray_buffer_size, traverse_grid

_LN2 = math.log(2.0)
# Indices into the float64 `state` array of the kernel.
_S_ENTROPY, _S_UID, _S_PREV_X, _S_PREV_Y, _S_HAS_PREV, _S_N_TOUCHED, _S_N_CHANGED = range(7)
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
) = range(12)
# Cell classes kept in `cls`.
CLASS_UNKNOWN, CLASS_FREE, CLASS_WALL = 0, 1, 2


@njit(cache=True)
def cell_entropy_bits(lo):
    """Binary entropy (bits) of a cell with log-odds ``lo``."""
    a = abs(lo)
    e = np.exp(-a)
    return (np.log1p(e) + a * e / (1.0 + e)) / _LN2


@njit(cache=True)
def log_odds_to_u8(lo):
    """``floor(255 * P(free))``: 0 wall ... 255 free, 127 at log-odds 0."""
    p_free = 1.0 / (1.0 + np.exp(lo))
    v = int(np.floor(255.0 * p_free))
    return min(max(v, 0), 255)


@njit(cache=True)
def _u8_class(v):
    if v <= U8_WALL_MAX:
        return CLASS_WALL
    if v >= U8_FREE_MIN:
        return CLASS_FREE
    return CLASS_UNKNOWN


@njit(cache=True)
def _apply(cell, delta, lo, cls, inside, stamp, touched, old_cls, state, lmin, lmax):
    """Add ``delta`` to one cell's log-odds; returns the entropy decrease (bits)."""
    if not inside[cell]:
        return 0.0
    uid = np.int64(state[_S_UID])
    if stamp[cell] != uid:
        n = np.int64(state[_S_N_TOUCHED])
        if n >= touched.shape[0]:
            return 0.0
        stamp[cell] = uid
        touched[n] = cell
        old_cls[n] = cls[cell]
        state[_S_N_TOUCHED] = n + 1
    old = lo[cell]
    new = np.float32(min(max(old + delta, lmin), lmax))
    if new == old:
        return 0.0
    lo[cell] = new
    return cell_entropy_bits(old) - cell_entropy_bits(new)


@njit(cache=True)
def _wall_piece(
    s_a, s_b, dk, j0, j1, rows, cols, t0, t1, l_tot, n_cols, params, arrays_lo, cls, inside,
    stamp, touched, old_cls, state,
):  # fmt: skip
    """Eq. 6 over cells ``j0..j1-1`` of a piece ``[s_a, s_b]`` (cell units) holding ``dk`` walls."""
    res = params[_P_RES]
    sub = (s_b - s_a) / dk
    sigma = max(params[_P_SMIN] / res, params[_P_SFRAC] * sub)
    amp = (params[_P_PEAK] - 0.5) * min(1.0, params[_P_LREF] / (sub * res))
    inv2s2 = 1.0 / (2.0 * sigma * sigma)
    gain = 0.0
    for j in range(j0, j1):
        s = 0.5 * (t0[j] + t1[j]) * l_tot
        q = int(np.floor((s - s_a) / sub))
        q = min(max(q, 0), dk - 1)
        c = s_a + (q + 0.5) * sub
        x = amp * np.exp(-(s - c) * (s - c) * inv2s2)
        if x < 1e-3:
            continue
        p = 0.5 + x
        delta = np.log(p / (1.0 - p))
        cell = rows[j] * n_cols + cols[j]
        gain += _apply(
            cell, delta, arrays_lo, cls, inside, stamp, touched, old_cls, state,
            params[_P_LMIN], params[_P_LMAX],
        )  # fmt: skip
    return gain


@njit(cache=True)
def _ray_update(
    r, k_robot, gx, gy, rgx, rgy, extend, n_rows, n_cols, params, raster, thresholds, n_thr,
    lo, cls, inside, stamp, touched, old_cls, state, rows, cols, t0, t1, anc_j, anc_s, anc_k,
):  # fmt: skip
    """Segment the ray of router ``r`` at earlier trajectory points and update every piece."""
    dx = gx - rgx
    dy = gy - rgy
    dist = np.sqrt(dx * dx + dy * dy)
    if dist < 1e-9:
        return 0.0
    if extend:
        ext = (n_rows + n_cols + 2.0) / dist
        ex = gx + dx * ext
        ey = gy + dy * ext
    else:
        ex = gx
        ey = gy
    n = traverse_grid(rgx, rgy, ex, ey, n_rows, n_cols, rows, cols, t0, t1)
    if n == 0:
        return 0.0
    l_tot = np.sqrt((ex - rgx) ** 2 + (ey - rgy) ** 2)
    t_robot = dist / l_tot
    # Robot's cell on the ray: the first whose exit parameter reaches the robot.
    i_r = n - 1
    for j in range(n):
        if t1[j] >= t_robot:
            i_r = j
            break
    lmin = params[_P_LMIN]
    lmax = params[_P_LMAX]
    min_wall_piece = 2.0 * params[_P_RADIUS] / params[_P_RES]
    # Anchors: router (k = 0), earlier trajectory cells, robot, first trajectory cell beyond.
    n_anc = 0
    anc_j[0] = -1
    anc_s[0] = 0.0
    anc_k[0] = 0
    n_anc = 1
    for j in range(i_r):
        f = raster[r, rows[j], cols[j]]
        if f == f:
            anc_j[n_anc] = j
            anc_s[n_anc] = 0.5 * (t0[j] + t1[j]) * l_tot
            anc_k[n_anc] = k_from_thresholds(f, thresholds[r], n_thr[r])
            n_anc += 1
    anc_j[n_anc] = i_r
    anc_s[n_anc] = dist
    anc_k[n_anc] = k_robot
    n_anc += 1
    if extend:
        for j in range(i_r + 1, n):
            f = raster[r, rows[j], cols[j]]
            if f == f:
                anc_j[n_anc] = j
                anc_s[n_anc] = 0.5 * (t0[j] + t1[j]) * l_tot
                anc_k[n_anc] = k_from_thresholds(f, thresholds[r], n_thr[r])
                n_anc += 1
                break
    gain = 0.0
    for a in range(n_anc - 1):
        j0 = anc_j[a] + 1
        j1 = anc_j[a + 1]
        if j1 <= j0:
            continue
        dk = anc_k[a + 1] - anc_k[a]
        if dk == 0:
            for j in range(j0, j1):
                cell = rows[j] * n_cols + cols[j]
                gain += _apply(
                    cell, params[_P_FREE], lo, cls, inside, stamp, touched, old_cls, state,
                    lmin, lmax,
                )  # fmt: skip
        elif dk > 0:
            s_a = anc_s[a]
            s_b = anc_s[a + 1]
            if a > 0 and s_b - s_a < min_wall_piece:
                continue
            gain += _wall_piece(
                s_a, s_b, dk, j0, j1, rows, cols, t0, t1, l_tot, n_cols, params, lo, cls,
                inside, stamp, touched, old_cls, state,
            )  # fmt: skip
    return gain


@njit(cache=True)
def _update_kernel(
    gx, gy, rssi, bumped, heading, routers_g, policy_all, extend, params, kest_da, kest_n,
    kest_dmin, kest_gap, ring, ring_pos, ring_count, fit_buf, fit_n, fit_stride, n_seen,
    next_refit, thresholds, n_thr, fitted, max_feature, feature, k_out, selected, dist_buf,
    lo, u8, cls, classified, inside, raster, stamp, touched, old_cls, changed, state,
    rows, cols, t0, t1, anc_j, anc_s, anc_k,
):  # fmt: skip
    n_rows = raster.shape[1]
    n_cols = raster.shape[2]
    n_r = rssi.shape[0]
    res = params[_P_RES]
    lmin = params[_P_LMIN]
    lmax = params[_P_LMAX]
    state[_S_UID] += 1.0
    state[_S_N_TOUCHED] = 0.0
    state[_S_N_CHANGED] = 0.0
    for r in range(n_r):
        dist_buf[r] = res * np.sqrt((gx - routers_g[r, 0]) ** 2 + (gy - routers_g[r, 1]) ** 2)
    due = add_samples(
        rssi, dist_buf, kest_da, kest_n, kest_dmin, kest_gap, ring, ring_pos, ring_count,
        fit_buf, fit_n, fit_stride, n_seen, next_refit, thresholds, n_thr, fitted, max_feature,
        feature, k_out,
    )  # fmt: skip
    gain = 0.0
    # Rule 1: footprint free; a bump marks the contact cell ahead occupied.
    rad = params[_P_RADIUS] / res
    rc = int(np.floor(gx))
    rr = int(np.floor(gy))
    r_lo = max(int(np.floor(gy - rad)) - 1, 0)
    r_hi = min(int(np.floor(gy + rad)) + 1, n_rows - 1)
    c_lo = max(int(np.floor(gx - rad)) - 1, 0)
    c_hi = min(int(np.floor(gx + rad)) + 1, n_cols - 1)
    for i in range(r_lo, r_hi + 1):
        for j in range(c_lo, c_hi + 1):
            ddx = j + 0.5 - gx
            ddy = i + 0.5 - gy
            if ddx * ddx + ddy * ddy <= rad * rad or (i == rr and j == rc):
                gain += _apply(
                    i * n_cols + j, params[_P_FOOT], lo, cls, inside, stamp, touched, old_cls,
                    state, lmin, lmax,
                )  # fmt: skip
    if bumped and heading == heading:
        reach = rad + 0.5
        bc = int(np.floor(gx + reach * np.cos(heading)))
        br = int(np.floor(gy + reach * np.sin(heading)))
        if 0 <= br < n_rows and 0 <= bc < n_cols and not (br == rr and bc == rc):
            gain += _apply(
                br * n_cols + bc, params[_P_BUMP], lo, cls, inside, stamp, touched, old_cls,
                state, lmin, lmax,
            )  # fmt: skip
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
        gain += _ray_update(
            r, k_out[r], gx, gy, routers_g[r, 0], routers_g[r, 1], extend, n_rows, n_cols,
            params, raster, thresholds, n_thr, lo, cls, inside, stamp, touched, old_cls, state,
            rows, cols, t0, t1, anc_j, anc_s, anc_k,
        )  # fmt: skip
    # Trajectory raster (after the rays, so this reading is not its own anchor).
    n_traj = 0
    if state[_S_HAS_PREV] > 0.0:
        px = state[_S_PREV_X]
        py = state[_S_PREV_Y]
        if res * np.sqrt((gx - px) ** 2 + (gy - py) ** 2) <= params[_P_GAP]:
            n_traj = traverse_grid(px, py, gx, gy, n_rows, n_cols, rows, cols, t0, t1)
    for r in range(n_r):
        if k_out[r] < 0:
            continue
        f = np.float32(feature[r])
        for j in range(n_traj):
            raster[r, rows[j], cols[j]] = f
        raster[r, rr, rc] = f
    state[_S_PREV_X] = gx
    state[_S_PREV_Y] = gy
    state[_S_HAS_PREV] = 1.0
    # Refresh the uint8 map and classes of touched cells; record class changes.
    n_t = np.int64(state[_S_N_TOUCHED])
    n_c = 0
    for i in range(n_t):
        cell = touched[i]
        v = log_odds_to_u8(lo[cell])
        u8[cell] = v
        c = _u8_class(v)
        cls[cell] = c
        classified[cell] = c != CLASS_UNKNOWN
        if c != old_cls[i]:
            changed[n_c] = cell
            n_c += 1
    state[_S_N_CHANGED] = n_c
    state[_S_ENTROPY] -= gain
    return gain, due


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

    def __init__(
        self, grid: GridSpec, routers_xy, config: MapperConfig | None = None
    ) -> None:
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
        self.n_routers = routers.shape[0]
        self._routers_g = grid.world_to_grid(routers)
        self._params = np.array(
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
            ],
            dtype=np.float64,
        )
        self._k_estimator = KEstimator(self.n_routers, cfg)
        h, w = grid.shape
        self._inside = np.ones(h * w, np.bool_)
        if cfg.outer_bounds_m is not None:
            xs, ys = grid.cell_centres()
            xmin, ymin, xmax, ymax = cfg.outer_bounds_m
            self._inside[:] = ((xs >= xmin) & (xs <= xmax) & (ys >= ymin) & (ys <= ymax)).ravel()
        ray_n = ray_buffer_size(grid.shape)
        rad_cells = math.ceil(cfg.robot_radius_m / grid.resolution_m) + 2
        touched_cap = (2 * rad_cells + 1) ** 2 + 2 + self.n_routers * ray_n
        self._rows = np.empty(ray_n, np.int64)
        self._cols = np.empty(ray_n, np.int64)
        self._t0 = np.empty(ray_n, np.float64)
        self._t1 = np.empty(ray_n, np.float64)
        self._anc_j = np.empty(ray_n + 2, np.int64)
        self._anc_s = np.empty(ray_n + 2, np.float64)
        self._anc_k = np.empty(ray_n + 2, np.int64)
        self._touched = np.empty(touched_cap, np.int64)
        self._old_cls = np.empty(touched_cap, np.int8)
        self._changed = np.empty(touched_cap, np.int64)
        self._selected = np.empty(self.n_routers, np.int64)
        self._dist = np.empty(self.n_routers, np.float64)
        h, w = grid.shape
        self._lo = np.zeros(h * w, np.float32)
        self._u8 = np.full(h * w, U8_UNKNOWN, np.uint8)
        self._cls = np.zeros(h * w, np.int8)
        self._classified = np.zeros(h * w, np.bool_)
        self._raster = np.full((self.n_routers, h, w), np.nan, np.float32)
        self._stamp = np.zeros(h * w, np.int64)
        self._state = np.zeros(7, np.float64)
        self._lo_view = self._read_only(self._lo)
        self._u8_view = self._read_only(self._u8)
        self._classified_view = self._read_only(self._classified)
        self.reset()

    def reset(self) -> None:
        """Forget the map, the trajectory and the k-estimator (in place: views stay valid)."""
        self._lo.fill(0.0)
        self._u8.fill(U8_UNKNOWN)
        self._cls.fill(CLASS_UNKNOWN)
        self._classified.fill(False)
        self._raster.fill(np.nan)
        self._stamp.fill(0)
        self._state.fill(0.0)
        self._state[_S_ENTROPY] = float(self._inside.sum())
        self._k_estimator.reset()
        self.n_updates = 0

    def _read_only(self, flat: np.ndarray) -> np.ndarray:
        view = flat.reshape(self.grid.shape).view()
        view.flags.writeable = False
        return view

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
            x = float(position_xy[0])
            y = float(position_xy[1])
            n_pos = len(position_xy)
        except (TypeError, ValueError, IndexError) as exc:
            raise ConfigError(f"position_xy must be (x, y), got {position_xy!r}") from exc
        if n_pos != 2 or not (math.isfinite(x) and math.isfinite(y)):
            raise ConfigError(f"position_xy must be two finite numbers, got {position_xy!r}")
        ox, oy = self.grid.origin_xy
        res = self.grid.resolution_m
        gx = (x - ox) / res
        gy = (y - oy) / res
        if not (0.0 <= gx < self.grid.n_cols and 0.0 <= gy < self.grid.n_rows):
            raise ConfigError(
                f"position_xy {position_xy!r} lies outside the grid bounds {self.grid.bounds}"
            )
        rssi = rssi_dbm
        if not (isinstance(rssi, np.ndarray) and rssi.dtype == np.float64):
            rssi = np.asarray(rssi_dbm, dtype=np.float64)
        if rssi.shape != (self.n_routers,):
            raise ConfigError(f"rssi_dbm must have shape ({self.n_routers},), got {rssi.shape}")
        if not np.isfinite(rssi).all():
            raise ConfigError(
                f"rssi_dbm must be finite (use -100 dBm for 'not heard'), got {rssi.tolist()}"
            )
        if heading_rad is None:
            heading = math.nan
        else:
            heading = float(heading_rad)
            if not math.isfinite(heading):
                raise ConfigError(f"heading_rad must be finite or None, got {heading_rad!r}")
        ke = self._k_estimator
        gain, due = _update_kernel(
            gx, gy, rssi, bool(bumped), heading, self._routers_g,
            self.config.router_policy == "all", self.config.extend_past_robot, self._params,
            *ke._kernel_args(), ke._feature, ke._k, self._selected, self._dist,
            self._lo, self._u8, self._cls, self._classified, self._inside, self._raster,
            self._stamp, self._touched, self._old_cls, self._changed, self._state,
            self._rows, self._cols, self._t0, self._t1, self._anc_j, self._anc_s, self._anc_k,
        )  # fmt: skip
        if due:
            ke.refit()
        self.n_updates += 1
        return float(gain)

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
