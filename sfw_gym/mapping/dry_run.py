"""The mapper's update, run dry: the bits a path of hypothetical readings would buy.

:class:`DryRun` snapshots a :class:`~sfw_gym.mapping.sparse.SparseInverseKVisibility` and runs
its update, step by step along candidate paths, on scratch copies of the belief: the same
compiled rules (the footprint, the ray cut at earlier trajectory points, every piece by its
Delta k, the trajectory raster written after the rays), so the hypothetical poses cut later rays
as real ones would. What a dry run cannot know it is told: per step, the router whose ray the
mapper would follow and that router's k there (a planner reads both off a predicted map). No
RSSI is read and the k-estimator does not move: a hypothetical reading's k is written into the
raster as a feature that the current thresholds read back as that k. Bumps are not simulated.

After each path the scratch copies are restored (the cells it touched, from the mapper), so
every path starts from the belief of the snapshot. A snapshot is the dry run's own copy: the
mapper moves on without it.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numba import njit

from sfw_gym.core.errors import ConfigError
from sfw_gym.mapping.grid import CLASS_UNKNOWN, GridSpec, u8_class
from sfw_gym.mapping.sparse import (
    _N_STATE,
    _S_HAS_PREV,
    _S_N_TOUCHED,
    _S_PREV_X,
    _S_PREV_Y,
    _S_UID,
    MapperState,
    SparseInverseKVisibility,
    _begin_update,
    _classify_touched,
    _footprint_update,
    _ray_update,
    _trajectory_cells,
    inside_mask,
    kernel_buffers,
    kernel_params,
    log_odds_to_u8,
)


class DryRun:
    """The mapper's update along hypothetical paths, on a snapshot of its belief.

    Args:
        grid: The map's geometry.
        routers_xy: ``(R, 2)`` router positions (world metres).
        log_odds: ``(H, W)`` the belief's log-odds now (copied).
        state: The mapper's other state now (:meth:`SparseInverseKVisibility.state`; copied).

    :meth:`of_mapper` and :meth:`of_view` build one from a mapper or from the robot's view.
    """

    def __init__(
        self, grid: GridSpec, routers_xy: np.ndarray, log_odds: np.ndarray, state: MapperState
    ) -> None:
        cfg = state.config
        lo = np.array(log_odds, np.float32).ravel()  # a copy: the mapper moves on
        n_cells = lo.size
        if lo.shape != (grid.shape[0] * grid.shape[1],):
            raise ConfigError(f"DryRun: log_odds must have the grid's shape {grid.shape}")
        self.grid = grid
        self.n_routers = len(routers_xy)
        self._routers_g = grid.world_to_grid(np.asarray(routers_xy, np.float64).reshape(-1, 2))
        self._extend = cfg.extend_past_robot
        self._params = kernel_params(grid, cfg)
        self._thresholds = np.ascontiguousarray(state.k_thresholds)
        self._n_thr = np.ascontiguousarray(state.n_thresholds)
        ent = np.array(state.cell_entropy_bits, np.float64).ravel()
        u8, cls = _derived_maps(lo)
        inside = inside_mask(grid, cfg)
        self._base = (lo, ent, u8, cls, cls != CLASS_UNKNOWN, inside, np.zeros(0, np.int64))
        # scratch copies (the stamp starts afresh: only its equality with the update's uid counts)
        self._maps = (
            lo.copy(),
            ent.copy(),
            u8.copy(),
            cls.copy(),
            cls != CLASS_UNKNOWN,
            inside,
            np.zeros(n_cells, np.int64),
        )
        self._base_raster = np.array(state.trajectory_features, np.float32)
        self._raster = self._base_raster.copy()
        self._state = np.zeros(_N_STATE, np.float64)
        if state.previous_xy is not None:
            gx, gy = grid.world_to_grid(np.asarray(state.previous_xy, np.float64))
            self._state[_S_PREV_X], self._state[_S_PREV_Y], self._state[_S_HAS_PREV] = gx, gy, 1
        self._base_state = self._state.copy()
        self._track, self._ray, self._anchors = kernel_buffers(
            grid, cfg, self.n_routers, self._state
        )
        self._undo = np.empty(n_cells, np.int64)
        self._dirty = np.zeros(n_cells, np.int64)
        self._raster_undo = np.empty(self._raster.size, np.int64)
        self._raster_dirty = np.zeros(self._raster.size, np.int64)
        self._mark = np.zeros(1, np.int64)

    @classmethod
    def of_mapper(cls, mapper: SparseInverseKVisibility) -> DryRun:
        """A snapshot of ``mapper`` now."""
        if not isinstance(mapper, SparseInverseKVisibility):
            raise ConfigError(f"mapper must be a SparseInverseKVisibility, got {mapper!r}")
        return cls(mapper.grid, mapper.routers_xy, mapper.log_odds, mapper.state())

    @classmethod
    def of_view(cls, view: Any) -> DryRun:
        """A snapshot of the robot's own mapper, as its view
        (:class:`~sfw_gym.navigation.view.RobotView`, a layer above) shows it."""
        if view.mapper_state is None:
            raise ConfigError("DryRun.of_view: this view carries no mapper_state")
        return cls(view.grid, view.routers_xy, view.log_odds, view.mapper_state)

    def path_gains(
        self, xy: np.ndarray, router: np.ndarray, k: np.ndarray, starts: np.ndarray | None = None
    ) -> np.ndarray:
        """Bits each hypothetical reading would gain, in order along its path.

        Args:
            xy: ``(N, 2)`` reading positions in world metres (inside the grid), the paths one
                after another.
            router: ``(N,)`` the router whose ray the mapper follows at each (-1: none).
            k: ``(N,)`` that router's k there (walls between it and the position).
            starts: Where each path begins in ``xy`` (``(C,)``, ascending, from 0); every path
                starts from the snapshot's belief. Default: one path.

        Returns:
            ``(N,)`` bits per reading.
        """
        grid = self.grid
        g = grid.world_to_grid(np.asarray(xy, np.float64).reshape(-1, 2))
        n = len(g)
        router = np.broadcast_to(np.asarray(router, np.int64), (n,))
        k = np.broadcast_to(np.asarray(k, np.int64), (n,))
        if n and not (
            (g[:, 0] >= 0).all()
            and (g[:, 0] < grid.shape[1]).all()
            and (g[:, 1] >= 0).all()
            and (g[:, 1] < grid.shape[0]).all()
        ):
            raise ConfigError("DryRun.path_gains: every position must lie inside the grid")
        if n and ((router < -1) | (router >= self.n_routers)).any():
            top = self.n_routers - 1
            raise ConfigError(f"DryRun.path_gains: router indices must be -1..{top}")
        bounds = np.append(np.zeros(1, np.int64) if starts is None else starts, n).astype(np.int64)
        if bounds[0] != 0 or (np.diff(bounds) < 0).any():
            raise ConfigError(f"DryRun.path_gains: starts must ascend from 0, got {starts!r}")
        out = np.zeros(n, np.float64)
        _dry_paths(
            np.ascontiguousarray(g),
            np.ascontiguousarray(router),
            np.ascontiguousarray(k),
            bounds,
            self._routers_g,
            self._extend,
            self._params,
            self._thresholds,
            self._n_thr,
            self._base,
            self._base_raster,
            self._base_state,
            self._maps,
            self._raster,
            self._track,
            self._ray,
            self._anchors,
            (self._undo, self._dirty, self._raster_undo, self._raster_dirty, self._mark),
            out,
        )
        return out


@njit(cache=True)
def _derived_maps(lo):  # pragma: no cover (compiled)
    """Per cell, as the mapper keeps them: the uint8 belief and the class."""
    n = lo.size
    u8 = np.empty(n, np.uint8)
    cls = np.empty(n, np.int8)
    for i in range(n):
        u8[i] = log_odds_to_u8(np.float64(lo[i]))
        cls[i] = u8_class(u8[i])
    return u8, cls


@njit(cache=True)
def feature_for_k(k, thresholds, n_thr):
    """A raster feature that :func:`~sfw_gym.mapping.k_estimation.k_from_thresholds` reads as
    ``k`` (capped at ``n_thr``): the k-th largest threshold, or one above them all for 0."""
    if n_thr == 0:
        return 0.0
    t = np.sort(thresholds[:n_thr])[::-1]
    if k <= 0:
        return t[0] + 1.0
    return t[min(k, n_thr) - 1]


@njit(cache=True)
def _dry_paths(
    g,
    router,
    k,
    bounds,
    routers_g,
    extend,
    params,
    thresholds,
    n_thr,
    base_maps,
    base_raster,
    base_state,
    maps,
    raster,
    track,
    ray,
    anchors,
    undo_log,
    out,
):  # pragma: no cover (compiled)
    undo, dirty, raster_undo, raster_dirty, mark_box = undo_log
    lo, ent, u8, cls, classified, _, _ = maps
    b_lo, b_ent, b_u8, b_cls, b_classified, _, _ = base_maps
    state = track[3]
    rows, cols = ray[0], ray[1]
    _, n_rows, n_cols = raster.shape
    n_cells = n_rows * n_cols
    flat_raster = raster.reshape(-1)
    flat_base = base_raster.reshape(-1)
    for c in range(len(bounds) - 1):
        mark_box[0] += 1
        mark = mark_box[0]
        uid = state[_S_UID]
        for i in range(_N_STATE):
            state[i] = base_state[i]
        state[_S_UID] = uid
        n_undo = 0
        n_rundo = 0
        for i in range(bounds[c], bounds[c + 1]):
            gx, gy = g[i, 0], g[i, 1]
            _begin_update(state)
            gain = _footprint_update(gx, gy, False, np.nan, params, maps, track, n_rows, n_cols)
            r = router[i]
            k_r = -1
            if r >= 0:
                k_r = min(max(k[i], 0), n_thr[r])
                traj = (raster[r], thresholds[r], n_thr[r])
                gain += _ray_update(
                    k_r, gx, gy, routers_g[r], extend, params, traj, maps, track, ray, anchors
                )
            for t in range(np.int64(state[_S_N_TOUCHED])):
                cell = track[0][t]
                if dirty[cell] != mark:
                    dirty[cell] = mark
                    undo[n_undo] = cell
                    n_undo += 1
            n_traj = _trajectory_cells(gx, gy, params, state, ray, n_rows, n_cols)
            if r >= 0:
                f = np.float32(feature_for_k(k_r, thresholds[r], n_thr[r]))
                for j in range(n_traj + 1):
                    if j < n_traj:
                        cell = r * n_cells + rows[j] * n_cols + cols[j]
                    else:
                        cell = r * n_cells + int(np.floor(gy)) * n_cols + int(np.floor(gx))
                    flat_raster[cell] = f
                    if raster_dirty[cell] != mark:
                        raster_dirty[cell] = mark
                        raster_undo[n_rundo] = cell
                        n_rundo += 1
            _classify_touched(maps, track)
            out[i] = gain
        for j in range(n_undo):
            cell = undo[j]
            lo[cell] = b_lo[cell]
            ent[cell] = b_ent[cell]
            u8[cell] = b_u8[cell]
            cls[cell] = b_cls[cell]
            classified[cell] = b_classified[cell]
        for j in range(n_rundo):
            flat_raster[raster_undo[j]] = flat_base[raster_undo[j]]
