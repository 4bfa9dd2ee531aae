"""The mapper's update, run dry: the bits a path of hypothetical readings would buy (issue 51).

:class:`DryRun` snapshots a :class:`~sfw_gym.mapping.sparse.SparseInverseKVisibility` and runs
its update, step by step along candidate paths, on scratch copies of the belief: the same
compiled rules (the footprint, the ray cut at earlier trajectory points, every piece by its
Delta k, the trajectory raster written after the rays), so the hypothetical poses cut later rays
as real ones would. What a dry run cannot know it is told: per step, the router whose ray the
mapper would follow and that router's k there (a planner reads both off a predicted map). No
RSSI is read and the k-estimator does not move: a hypothetical reading's k is written into the
raster as a feature that the current thresholds read back as that k. Bumps are not simulated.

After each path the scratch copies are restored (the cells it touched, from the mapper), so
every path starts from the belief of the snapshot. A snapshot is valid until the mapper's next
update.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from sfw_gym.core.errors import ConfigError
from sfw_gym.mapping.k_estimation import KERNEL_ARG_N_THR, KERNEL_ARG_THRESHOLDS
from sfw_gym.mapping.sparse import (
    _N_STATE,
    _S_N_TOUCHED,
    _S_UID,
    SparseInverseKVisibility,
    _begin_update,
    _classify_touched,
    _footprint_update,
    _ray_update,
    _trajectory_cells,
)


class DryRun:
    """The mapper's update along hypothetical paths, on a snapshot of its belief.

    Args:
        mapper: The mapper to snapshot (read, never changed).
    """

    def __init__(self, mapper: SparseInverseKVisibility) -> None:
        if not isinstance(mapper, SparseInverseKVisibility):
            raise ConfigError(f"mapper must be a SparseInverseKVisibility, got {mapper!r}")
        self.mapper = mapper
        self._n_updates = mapper.n_updates
        n_cells = mapper._lo.size
        lo, ent, u8, cls, classified, inside, _ = mapper._maps
        # scratch copies (the stamp starts afresh: only its equality with the update's uid counts)
        self._maps = (
            lo.copy(),
            ent.copy(),
            u8.copy(),
            cls.copy(),
            classified.copy(),
            inside,
            np.zeros(n_cells, np.int64),
        )
        self._raster = mapper._raster.copy()
        cap = mapper._changed.size
        self._state = mapper._state.copy()
        self._state[_S_UID] = 0.0
        self._track = (
            np.empty(cap, np.int64),
            np.empty(cap, np.int8),
            np.empty(cap, np.int64),
            self._state,
        )
        self._ray = tuple(np.empty_like(a) for a in mapper._ray)
        self._anchors = tuple(np.empty_like(a) for a in mapper._anchors)
        self._undo = np.empty(n_cells, np.int64)
        self._dirty = np.zeros(n_cells, np.int64)
        self._raster_undo = np.empty(self._raster.size, np.int64)
        self._raster_dirty = np.zeros(self._raster.size, np.int64)
        self._mark = np.zeros(1, np.int64)

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
        if self.mapper.n_updates != self._n_updates:
            raise ConfigError("DryRun: the mapper was updated since the snapshot; take a new one")
        grid = self.mapper.grid
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
        if n and ((router < -1) | (router >= self.mapper.n_routers)).any():
            top = self.mapper.n_routers - 1
            raise ConfigError(f"DryRun.path_gains: router indices must be -1..{top}")
        bounds = np.append(np.zeros(1, np.int64) if starts is None else starts, n).astype(np.int64)
        if bounds[0] != 0 or (np.diff(bounds) < 0).any():
            raise ConfigError(f"DryRun.path_gains: starts must ascend from 0, got {starts!r}")
        m = self.mapper
        out = np.zeros(n, np.float64)
        _dry_paths(
            np.ascontiguousarray(g),
            np.ascontiguousarray(router),
            np.ascontiguousarray(k),
            bounds,
            m._routers_g,
            m.config.extend_past_robot,
            m._params,
            m._kest[KERNEL_ARG_THRESHOLDS],
            m._kest[KERNEL_ARG_N_THR],
            m._maps,
            m._raster,
            m._state,
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
