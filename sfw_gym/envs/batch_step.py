"""The explore env's step for many sub-envs in two compiled calls: the vector env's fast path.

:class:`BatchStepper` holds, per sub-env, the episode's arrays (walls, radio tables, the mapper's,
the tracker's and the observation builder's buffers, the histories) in one numba list, and its
scalar state (poses, counters) in one row of a float array. A batch step then moves every robot
whose disc touches no wall in one call (pymunk moves the others, in Python), and does the
reading, the map update, the metrics and the observations of every sub-env in a second call,
written straight into the batch's arrays. Every compiled line repeats an operation of the
env's Python step in the same IEEE order, or calls the same kernel, so each sub-env is the single
env with its seed, bit for bit (tests/envs/test_vector_env.py).

The env objects stay the record: :meth:`BatchStepper.sync` writes a sub-env's state back before
anything else reads or steps it, and :meth:`BatchStepper.load` reads it after.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np
from numba import njit
from numba.typed import List

from sfw_gym.core.constants import NOT_HEARD_DBM
from sfw_gym.core.exact_math import hypot, wrap_heading
from sfw_gym.envs.map_tracker import (
    _AGREE,
    _COVERED,
    _FREE_INTER,
    _INTERIOR_FOUND,
    _KNOWN_BOTH,
    _N_EST_FREE,
    _N_EST_WALL,
    _N_KNOWN,
    _WALL_NEAR,
)
from sfw_gym.envs.map_tracker import _apply as _track_changes
from sfw_gym.envs.observation import (
    RSSI_FLOOR_DBM,
    RSSI_SPAN_DB,
    TRAJECTORY_U8,
    copy_into,
    draw_rest_into,
)
from sfw_gym.mapping.sparse import _S_ENTROPY, _S_N_CHANGED, _S_N_TOUCHED, _update_kernel
from sfw_gym.world import robot as robot_module
from sfw_gym.world.radio import _rssi_range, crossing_scratch

# A sub-env's scalar state: one row of `BatchStepper.state`.
(X, Y, A, ODO_X, ODO_Y, ODO_T, BUMPED, CLEAR_X, CLEAR_Y, CLEAR_D, VX, VY, W, UNSYNCED, CALLBACK,
 STEPS, PATH_M, COLLISIONS, K_CORRECT, K_TOTAL, TO_50, TO_90, EST_X, EST_Y, EST_T, SQ_ERR, GAIN,
 N_ROWS, N_UPDATES, X0, Y0, A0, MOVED_M, MAX_STEPS, TRUE_T, ODO_TW, POSE_ERR, ENTROPY,
 NORMALS_USED) = range(39)  # fmt: skip
N_STATE = 39
#: Standard normals drawn ahead per sub-env (its generator is put back before Python uses it).
NORMALS_AHEAD = 512
# A sub-env's constants: one row of `BatchStepper.consts`.
(RADIUS, PERIOD, SUBSTEPS, TRANS_STD, HEAD_STD, WALL_R, NOISE_DB, SENSITIVITY,
 GX0, GY0, GX1, GY1, GRID_RES, OBS_CELLS_PER_PX, OBS_PAD_R, OBS_PAD_C, OBS_MAP_PX, OBS_CROP,
 OBS_WIDTH_M, OBS_HEIGHT_M, GRID_ROWS, GRID_COLS, SCALE, PENALTY, TARGET, MAX_K, SLOTS, TRUE_POSE,
 N_CELLS, N_FREE, N_INTERIOR, CAPACITY, NORMALS_PER_STEP) = range(33)  # fmt: skip
N_CONSTS = 33
# The five map metrics, in `MapTracker.metrics`' order.
METRICS = ("coverage", "map_iou", "free_iou", "wall_precision", "interior_wall_recall")
# The info entries the batched step writes per sub-env (a row of `BatchStepper.info_rows`).
FLOAT_INFO = (*METRICS, "k_accuracy", "path_length_m", "pose_error_m", "ate_m", "entropy_bits",
              "info_gain_bits")  # fmt: skip
INT_INFO = ("collisions", "steps_to_coverage_50", "steps_to_coverage_90", "max_steps")
POSE_INFO = ("true_pose", "odometry_pose", "pose_estimate")
N_INFO = len(FLOAT_INFO) + len(INT_INFO) + 3 * len(POSE_INFO)
_K_ACCURACY, _PATH, _POSE_ERROR, _ATE, _ENTROPY, _GAIN = range(len(METRICS), len(FLOAT_INFO))
_COLLISIONS, _TO_50, _TO_90, _MAX_STEPS = range(len(FLOAT_INFO), len(FLOAT_INFO) + len(INT_INFO))
_TRUE_POSE, _ODOMETRY_POSE, _POSE_ESTIMATE = range(len(FLOAT_INFO) + len(INT_INFO), N_INFO, 3)


@njit(cache=True)
def _ratio(num: float, den: float) -> float:
    return num / den if den else 0.0


_NO_WALLS = np.zeros((0, 4))  # numba's constant: read-only, as the walls are
_NO_WALLS.flags.writeable = False


@njit(cache=True)
def _short(active, state, consts, full_rows):
    """The ``active`` sub-envs whose histories are full (``full_rows``), or else whose normals
    drawn ahead may run out this step."""
    out = np.empty(active.shape[0], np.int64)
    k = 0
    for n in range(active.shape[0]):
        i = active[n]
        if full_rows:
            short = state[i, N_ROWS] >= consts[i, CAPACITY]
        else:
            short = state[i, NORMALS_USED] + consts[i, NORMALS_PER_STEP] > NORMALS_AHEAD
        if short:
            out[k] = i
            k += 1
    return out[:k]


@njit(cache=True)
def move_robots(active, commands, state, consts, parts):
    """The robots' motion (``Robot.step``; ``commands[n]``: sub-env ``active[n]``'s linear and
    angular speeds) of the sub-envs whose discs touch no wall this step; returns which moved
    here (the others need pymunk: a contact, or a bump last step)."""
    moved = np.zeros(active.shape[0], np.bool_)
    for n in range(active.shape[0]):
        i = active[n]
        s, c = state[i], consts[i]
        vi, wi = commands[n, 0], commands[n, 1]
        x0, y0, a0 = s[X], s[Y], s[A]
        if s[BUMPED]:
            continue
        reach = c[RADIUS] + abs(vi) * c[PERIOD] + robot_module._REACH_MARGIN_M
        walls = _NO_WALLS  # the sub-env's own only when near them (a list item costs ~0.7 µs)
        far = True
        if (
            s[CLEAR_D]
            - hypot(x0 - s[CLEAR_X], y0 - s[CLEAR_Y])
            - robot_module._CLEARANCE_ROUNDING_M
            < reach
        ):  # Robot._may_touch_wall, its pymunk query done here (up to rounding: it only
            # decides which walls drive_substeps checks, never where the robot goes)
            look = reach + robot_module._CLEARANCE_LOOKAHEAD_M
            s[CLEAR_X], s[CLEAR_Y] = x0, y0
            walls = parts[i][0]
            s[CLEAR_D] = min(look, robot_module.nearest_wall_m(walls, x0, y0) - c[WALL_R])
            far = s[CLEAR_D] >= reach
        clear, x, y, a, vx, vy = robot_module.drive_substeps(
            x0, y0, a0, vi, wi, vi * math.cos(a0), vi * math.sin(a0), c[PERIOD] / c[SUBSTEPS],
            int(c[SUBSTEPS]), _NO_WALLS if far else walls, c[RADIUS] + c[WALL_R],
        )  # fmt: skip
        if not clear:
            continue
        s[X0], s[Y0], s[A0] = x0, y0, a0
        s[X], s[Y], s[A] = x, y, a
        s[VX], s[VY], s[W] = vx, vy, wi
        s[UNSYNCED] = 1.0
        s[CALLBACK] = 0.0
        moved[n] = True
    return moved


@njit(cache=True)
def _redraw_touched(track, u8, n_cols, belief_px, px_rows, px_cols):
    """Bring the map image's belief channel up to date with the cells the update touched
    (``px_rows[r]``: the first image row sampling grid row r and how many do; ``px_cols``
    alike)."""
    touched = track[0]
    for t in range(int(track[3][_S_N_TOUCHED])):
        cell = touched[t]
        r, c = cell // n_cols, cell % n_cols
        i0, j0 = px_rows[r, 0], px_cols[c, 0]
        for i in range(i0, i0 + px_rows[r, 1]):
            for j in range(j0, j0 + px_cols[c, 1]):
                belief_px[i, j] = u8[cell]


def _pixels_of(src: np.ndarray, valid: np.ndarray, n_cells: int) -> np.ndarray:
    """Per grid row (or column): the first image row (column) sampling it, and how many do."""
    out = np.zeros((n_cells, 2), np.int64)
    for px, cell in enumerate(src.tolist()):
        if valid[px]:
            if out[cell, 1] == 0:
                out[cell, 0] = px
            out[cell, 1] += 1
    return out


@njit(cache=True)
def _normal(s, normals):
    """The sub-env's next standard normal (drawn ahead from its generator)."""
    z = normals[int(s[NORMALS_USED])]
    s[NORMALS_USED] += 1.0
    return z


@njit(cache=True)
def _odometry(s, c, normals):
    """``Robot.step``'s odometry from the move X0..X (its noise from ``normals``)."""
    x0, y0, a0 = s[X0], s[Y0], s[A0]
    dx, dy = s[X] - x0, s[Y] - y0
    c0, s0 = math.cos(a0), math.sin(a0)
    forward = c0 * dx + s0 * dy
    lateral = -s0 * dx + c0 * dy
    turn = s[A] - a0
    distance = hypot(dx, dy)
    if c[TRANS_STD] > 0.0 or c[HEAD_STD] > 0.0:
        trans_std = c[TRANS_STD] * distance
        e_f, e_l, e_t = _normal(s, normals), _normal(s, normals), _normal(s, normals)
        forward += trans_std * e_f
        lateral += trans_std * e_l
        turn += c[HEAD_STD] * e_t
    ox, oy, ot = s[ODO_X], s[ODO_Y], s[ODO_T]
    co, so = math.cos(ot), math.sin(ot)
    s[ODO_X] = ox + co * forward - so * lateral
    s[ODO_Y] = oy + so * forward + co * lateral
    s[ODO_T] = ot + turn
    s[MOVED_M] = distance


@njit(cache=True)
def sense_and_map(
    active, moved, state, consts, parts, obs_map, obs_local, obs_state, reward, terminated,
    truncated, synced, info, done, due,
):  # fmt: skip
    """The rest of the step of the ``active`` sub-envs (``SfWExploreEnv.step`` after the robot's
    motion): odometry, the reading, the histories, the map update, k-accuracy, the tracker, the
    observation, the reward, the episode's end and the info (columns as `FLOAT_INFO`,
    `INT_INFO`, `POSE_INFO`), each in row ``active[n]`` of its batch array; ``done[n]``: 1
    terminated, 2 truncated, -1 the pose outside the grid (the env raises); ``due[n]``: the
    k-estimator wants a refit. Returns whether any sub-env ended, is due or failed."""
    anything = False
    for n in range(active.shape[0]):
        i = active[n]
        s, c = state[i], consts[i]
        _, radio, mapper, tracker, builder, history, scratch, normals = parts[i]
        edges, edge_loss, wall_index, routers, radio_params, tables, origin, spacing = radio
        (routers_g, policy_all, extend, map_params, kest, feature, k_est, selected, dist_buf,
         raster, maps, track, ray, anchors) = mapper  # fmt: skip
        est_cls, truth_cls, near_wall, interior, found_by, offsets, counts = tracker
        belief_px, px_rows, px_cols, trajectory, router_px = builder
        rssi_rows, true_rows, odometry_rows, estimate_rows = history
        pts, mean_db, true_k, rssi, readings, crossings = scratch
        n_routers = routers.shape[0]
        if moved[n]:
            _odometry(s, c, normals)
        s[STEPS] += 1.0
        s[PATH_M] += s[MOVED_M]
        s[COLLISIONS] += s[BUMPED]
        # the reading at the true pose (RadioModel.measure_at)
        tx, ty, tt = s[X], s[Y], wrap_heading(s[A])
        pts[0, 0], pts[0, 1] = tx, ty
        _rssi_range(
            edges, edge_loss, wall_index, routers, pts, radio_params, tables, origin, spacing,
            mean_db, true_k, 0, 1, crossings,
        )  # fmt: skip
        for r in range(n_routers):
            db = mean_db[0, r]
            if c[NOISE_DB] > 0.0:
                db += 0.0 + c[NOISE_DB] * _normal(s, normals)
            reading = np.int32(np.rint(db))
            rssi[r] = NOT_HEARD_DBM if reading < c[SENSITIVITY] else reading
        # the pose it maps at, and the histories
        if c[TRUE_POSE]:
            px, py, pt = tx, ty, tt
        else:
            px, py, pt = s[ODO_X], s[ODO_Y], wrap_heading(s[ODO_T])
        s[EST_X], s[EST_Y], s[EST_T] = px, py, pt
        s[TRUE_T], s[ODO_TW] = tt, wrap_heading(s[ODO_T])
        s[POSE_ERR] = hypot(px - tx, py - ty)
        row = int(s[N_ROWS])
        for r in range(n_routers):
            rssi_rows[row, r] = rssi[r]
        true_rows[row, 0], true_rows[row, 1] = tx, ty
        odometry_rows[row, 0], odometry_rows[row, 1] = px, py
        estimate_rows[row, 0], estimate_rows[row, 1], estimate_rows[row, 2] = px, py, pt
        s[N_ROWS] = row + 1
        s[SQ_ERR] += (px - tx) ** 2 + (py - ty) ** 2
        # the map update (SfWExploreEnv._map_at)
        gain = 0.0
        if c[GX0] <= px < c[GX1] and c[GY0] <= py < c[GY1]:
            gx = (px - c[GX0]) / c[GRID_RES]
            gy = (py - c[GY0]) / c[GRID_RES]
            if not (0.0 <= gx < c[GRID_COLS] and 0.0 <= gy < c[GRID_ROWS]):
                done[n] = -1  # outside the grid although inside its bounds: the env raises
                return True
            for r in range(n_routers):
                readings[r] = rssi[r]
            gain, due[n] = _update_kernel(
                gx, gy, readings, s[BUMPED] != 0.0, pt, routers_g, policy_all, extend,
                map_params, kest, feature, k_est, selected, dist_buf, raster, maps, track, ray,
                anchors,
            )  # fmt: skip
            s[N_UPDATES] += 1.0
            _redraw_touched(track, maps[2], int(c[GRID_COLS]), belief_px, px_rows, px_cols)
            n_changed = int(track[3][_S_N_CHANGED])
            if n_changed:
                _track_changes(
                    track[2][:n_changed], maps[2], est_cls, truth_cls, near_wall, interior,
                    found_by, offsets, int(c[GRID_COLS]), counts,
                )  # fmt: skip
            for r in range(n_routers):
                if rssi[r] > NOT_HEARD_DBM and k_est[r] >= 0:
                    s[K_TOTAL] += 1.0
                    s[K_CORRECT] += k_est[r] == min(true_k[0, r], c[MAX_K])
        s[GAIN] = gain
        s[ENTROPY] = track[3][_S_ENTROPY]
        # the observation (ObservationBuilder.mark_visited and build)
        cells_px, map_px = c[OBS_CELLS_PER_PX], int(c[OBS_MAP_PX])
        pr = math.floor((py - c[GY0]) / c[GRID_RES] / cells_px + c[OBS_PAD_R])
        pc = math.floor((px - c[GX0]) / c[GRID_RES] / cells_px + c[OBS_PAD_C])
        pr, pc = min(max(pr, 0), map_px - 1), min(max(pc, 0), map_px - 1)
        trajectory[pr, pc] = TRAJECTORY_U8
        rows, cols = int(c[GRID_ROWS]), int(c[GRID_COLS])
        cr = min(max(int((py - c[GY0]) / c[GRID_RES]), 0), rows - 1)
        cc = min(max(int((px - c[GX0]) / c[GRID_RES]), 0), cols - 1)
        copy_into(obs_map[i, 0], belief_px)
        draw_rest_into(
            maps[2].reshape((rows, cols)), trajectory, router_px, (pr, pc, cr, cc),
            int(c[OBS_CROP]), obs_map[i], obs_local[i],
        )  # fmt: skip
        out = obs_state[i]
        slots = int(c[SLOTS])
        for r in range(slots):
            db = rssi[r] if r < n_routers else NOT_HEARD_DBM
            if db > RSSI_FLOOR_DBM:
                out[r] = min(max((db - RSSI_FLOOR_DBM) / RSSI_SPAN_DB, 0.0), 1.0)
                out[slots + r] = 1.0
            else:
                out[r] = 0.0
                out[slots + r] = 0.0
        out[2 * slots] = s[BUMPED]
        out[2 * slots + 1] = min(max((px - c[GX0]) / c[OBS_WIDTH_M], 0.0), 1.0)
        out[2 * slots + 2] = min(max((py - c[GY0]) / c[OBS_HEIGHT_M], 0.0), 1.0)
        out[2 * slots + 3] = math.sin(pt)
        out[2 * slots + 4] = math.cos(pt)
        out[2 * slots + 5] = counts[_N_KNOWN] / c[N_CELLS]
        # the reward, the metrics (MapTracker.metrics) and the episode's end
        reward[i] = c[SCALE] * gain - c[PENALTY] * s[BUMPED]
        inter = counts[_FREE_INTER]
        m = info[i]
        m[0] = _ratio(counts[_COVERED], c[N_FREE])
        m[1] = _ratio(counts[_AGREE], counts[_KNOWN_BOTH])
        m[2] = _ratio(inter, counts[_N_EST_FREE] + c[N_FREE] - inter)
        m[3] = _ratio(counts[_WALL_NEAR], counts[_N_EST_WALL])
        m[4] = _ratio(counts[_INTERIOR_FOUND], c[N_INTERIOR])
        if s[TO_50] < 0 and m[0] >= 0.5:
            s[TO_50] = s[STEPS]
        if s[TO_90] < 0 and m[0] >= 0.9:
            s[TO_90] = s[STEPS]
        m[_K_ACCURACY] = s[K_CORRECT] / s[K_TOTAL] if s[K_TOTAL] else 0.0
        m[_PATH], m[_POSE_ERROR] = s[PATH_M], s[POSE_ERR]
        m[_ATE] = math.sqrt(s[SQ_ERR] / s[N_ROWS])
        m[_ENTROPY], m[_GAIN] = s[ENTROPY], s[GAIN]
        m[_COLLISIONS], m[_TO_50], m[_TO_90] = s[COLLISIONS], s[TO_50], s[TO_90]
        m[_MAX_STEPS] = s[MAX_STEPS]
        m[_TRUE_POSE], m[_TRUE_POSE + 1], m[_TRUE_POSE + 2] = tx, ty, tt
        m[_ODOMETRY_POSE], m[_ODOMETRY_POSE + 1] = s[ODO_X], s[ODO_Y]
        m[_ODOMETRY_POSE + 2] = s[ODO_TW]
        m[_POSE_ESTIMATE], m[_POSE_ESTIMATE + 1], m[_POSE_ESTIMATE + 2] = px, py, pt
        if m[0] >= c[TARGET]:
            done[n] = 1
        elif s[STEPS] >= s[MAX_STEPS]:
            done[n] = 2
        terminated[i] = done[n] == 1
        truncated[i] = done[n] == 2
        synced[i] = False
        anything |= done[n] != 0 or due[n]
    return anything


# The typed list's methods compiled here and cached: numba's own compile again in every
# process (2.5 s at a vector env's first autoreset, measured).
@njit(cache=True)
def _new_list(item):
    """A typed list holding ``item``."""
    out = List()
    out.append(item)
    return out


@njit(cache=True)
def _put(items, i, item):
    """``items[i] = item``, the list first padded with ``item`` up to ``i``."""
    while len(items) <= i:
        items.append(item)
    items[i] = item


def _read_only(array: np.ndarray) -> np.ndarray:
    """A read-only view: one numba type whether the array came read-only or unpickled."""
    view = array.view()
    view.flags.writeable = False
    return view


def _float_tuple(values: Any) -> tuple[Any, ...]:
    """A tuple with Python numbers as floats, bools kept (one numba type for every sub-env)."""
    return tuple(v if isinstance(v, np.ndarray | bool | np.bool_) else float(v) for v in values)


class _Episode(NamedTuple):
    """What a sub-env's batched state was gathered from, and the Python handles to keep."""

    env: Any
    buffers: tuple[np.ndarray, ...]  # the histories' arrays (they move when they grow)
    rng: np.random.Generator
    normals: np.ndarray  # drawn ahead from ``rng``
    belief_px: np.ndarray  # the map image's belief channel, kept up to date


class BatchStepper:
    """The compiled state of ``num_envs`` explore sub-envs (see the module doc)."""

    def __init__(self, num_envs: int) -> None:
        self.state = np.zeros((num_envs, N_STATE))
        self.consts = np.zeros((num_envs, N_CONSTS))
        self.parts: Any = None  # a numba typed list, made at the first attach
        self._episodes: list[Any] = [None] * num_envs  # an _Episode once attached
        self.synced = np.ones(num_envs, np.bool_)
        self.info_rows = np.zeros((num_envs, N_INFO))
        self.info_order: tuple[str, ...] = ()  # the keys of `SfWExploreEnv._info`, in order
        # the generator's state before the normals of each sub-env were drawn ahead (None: none)
        self._drawn_from: list[Any] = [None] * num_envs

    # ------------------------------------------------------------------ env <-> arrays
    def load(self, i: int, env: Any) -> None:
        """Read sub-env ``i``'s state (after its reset, or a step it took in Python)."""
        robot = env.scene.robot
        self.load_robot(i, robot, 0.0)
        s = self.state[i]
        s[STEPS], s[PATH_M], s[COLLISIONS] = env.steps, env.path_length_m, env.collisions
        s[K_CORRECT], s[K_TOTAL] = env.k_correct, env.k_total
        s[TO_50], s[TO_90] = env.steps_to[0.5], env.steps_to[0.9]
        s[EST_X], s[EST_Y], s[EST_T] = env.pose_estimate
        s[SQ_ERR], s[GAIN] = env._squared_pose_errors, env.last_gain_bits
        s[N_ROWS], s[N_UPDATES] = len(env.rssi_history), env.mapper.n_updates
        s[MAX_STEPS] = env.episode_max_steps
        s[TRUE_T], s[ODO_TW] = robot.pose[2], robot.odometry_pose[2]
        s[POSE_ERR] = math.dist(env.pose_estimate[:2], robot.pose[:2])
        s[ENTROPY] = env.mapper.entropy_bits
        histories = (env.rssi_history, env.true_path, env.odometry_trajectory, env.pose_estimates)
        buffers = tuple(h._data for h in histories)
        self._put_back_generator(i)
        if (
            self._episodes[i] is None
            or self._episodes[i].env is not env
            or any(a is not b for a, b in zip(self._episodes[i].buffers, buffers, strict=True))
        ):
            self._attach(i, env, buffers)
            if not self.info_order:  # the env's own order: one place for it
                self.info_order = tuple(env._info(terminal=False))
        else:  # the map may have changed outside: redraw its image
            self._episodes[i].belief_px[:] = env.obs_builder.image_of(env.mapper.occupancy_u8)
        self.synced[i] = True

    def load_robot(self, i: int, robot: Any, distance_m: float) -> None:
        """Read sub-env ``i``'s robot after it stepped in Python (``distance_m``: its move)."""
        s = self.state[i]
        s[X], s[Y], s[A] = robot._xya
        s[ODO_X], s[ODO_Y], s[ODO_T] = robot._odometry
        s[BUMPED] = robot._bumped
        s[CLEAR_X], s[CLEAR_Y], s[CLEAR_D] = robot._clearance
        s[UNSYNCED] = robot._unsynced is not None
        if robot._unsynced is not None:
            _, _, _, s[VX], s[VY], s[W] = robot._unsynced
        s[CALLBACK] = robot._callback_on
        s[MOVED_M] = distance_m

    def _attach(self, i: int, env: Any, buffers: tuple[np.ndarray, ...]) -> None:
        """Gather sub-env ``i``'s episode arrays and constants (after a reset or a history's
        growth)."""
        scene, cfg = env.scene, env.config
        robot, radio, mapper, tracker, builder = (
            scene.robot, scene.radio, env.mapper, env.tracker, env.obs_builder,
        )  # fmt: skip
        n_r = len(radio.routers)
        ke = mapper._k_estimator
        table, origin, spacing = radio._shadow_args
        parts = (
            _read_only(robot._walls),
            (*map(_read_only, (radio.floorplan.edges, radio._edge_loss_db)),
             tuple(map(_read_only, radio._wall_index)),
             *map(_read_only, (radio.routers, radio._params, table, origin)), float(spacing)),
            (mapper._routers_g, bool(mapper._policy_all), bool(mapper.config.extend_past_robot),
             mapper._params, _float_tuple(mapper._kest), ke._feature, ke._k, mapper._selected,
             mapper._dist, mapper._raster, mapper._maps, mapper._track, mapper._ray,
             mapper._anchors),
            (tracker._est_cls, tracker._truth_cls, tracker._near_wall, tracker._interior,
             tracker._found_by, tracker._offsets, tracker._counts),
            (builder.image_of(mapper.occupancy_u8),
             _pixels_of(builder._src_r, ~builder._pad.all(axis=1), mapper.grid.shape[0]),
             _pixels_of(builder._src_c, ~builder._pad.all(axis=0), mapper.grid.shape[1]),
             builder._trajectory, builder._routers),
            buffers,
            (np.zeros((1, 2)), np.zeros((1, n_r)), np.zeros((1, n_r), np.int32),
             np.zeros(n_r, np.int32), np.zeros(n_r), crossing_scratch(radio.floorplan.edges)),
            np.zeros(NORMALS_AHEAD),
        )  # fmt: skip
        if self.parts is None:
            self.parts = _new_list(parts)
        _put(self.parts, i, parts)
        self._episodes[i] = _Episode(env, buffers, radio.rng, parts[-1], parts[4][0])
        self._drawn_from[i] = None
        self.state[i, NORMALS_USED] = NORMALS_AHEAD
        noisy_radio = radio.config.noise_sigma_db > 0
        self.consts[i, NORMALS_PER_STEP] = 3 * robot._noisy + n_r * noisy_radio
        self.consts[i, CAPACITY] = min(len(b) for b in buffers)
        rc, grid, ob = cfg.robot, env.grid, builder
        x0, y0, x1, y1 = env._grid_bounds
        c = self.consts[i]
        c[RADIUS] = rc.radius_m
        c[PERIOD], c[SUBSTEPS], c[WALL_R] = (
            rc.control_period_s,
            rc.physics_substeps,
            rc.wall_radius_m,
        )
        c[TRANS_STD], c[HEAD_STD] = rc.odometry_translation_std, rc.odometry_heading_std_rad
        c[NOISE_DB], c[SENSITIVITY] = radio.config.noise_sigma_db, radio.config.sensitivity_dbm
        c[GX0], c[GY0], c[GX1], c[GY1], c[GRID_RES] = x0, y0, x1, y1, grid.resolution_m
        c[GRID_ROWS], c[GRID_COLS] = grid.shape
        c[OBS_CELLS_PER_PX], c[OBS_PAD_R], c[OBS_PAD_C] = ob.cells_per_px, ob._pad_r, ob._pad_c
        c[OBS_MAP_PX], c[OBS_CROP] = ob.map_px, ob.crop_px
        c[OBS_WIDTH_M], c[OBS_HEIGHT_M] = ob._width_m, ob._height_m
        c[SCALE], c[PENALTY] = cfg.reward.reward_scale, cfg.reward.collision_penalty
        c[TARGET], c[MAX_K], c[SLOTS] = (
            cfg.reward.coverage_target,
            cfg.mapper.max_k,
            ob.n_router_slots,
        )
        c[TRUE_POSE] = cfg.explore.pose_source == "true"
        c[N_CELLS], c[N_FREE], c[N_INTERIOR] = (
            tracker._n_cells,
            tracker._n_truth_free,
            tracker._n_interior,
        )

    def draw_ahead(self, active: np.ndarray) -> None:
        """Draw normals ahead for the ``active`` sub-envs that may run out this step."""
        for i in _short(active, self.state, self.consts, False).tolist():
            self._put_back_generator(i)
            rng, normals = self._episodes[i].rng, self._episodes[i].normals
            self._drawn_from[i] = rng.bit_generator.state
            normals[:] = rng.standard_normal(NORMALS_AHEAD)
            self.state[i, NORMALS_USED] = 0

    def _put_back_generator(self, i: int) -> None:
        """Give sub-env ``i``'s generator the state it would have without the draws ahead."""
        drawn_from = self._drawn_from[i]
        if drawn_from is not None:
            rng = self._episodes[i].rng
            rng.bit_generator.state = drawn_from
            used = int(self.state[i, NORMALS_USED])
            if used:
                rng.standard_normal(used)
            self._drawn_from[i] = None
            self.state[i, NORMALS_USED] = NORMALS_AHEAD

    def sync(self, i: int, env: Any) -> None:
        """Write sub-env ``i``'s state back into its env objects (before anything reads them)."""
        self._put_back_generator(i)
        if self.synced[i]:
            return
        from sfw_gym.world import Pose

        s = self.state[i].tolist()
        robot = env.scene.robot
        robot._xya = (s[X], s[Y], s[A])
        robot._odometry = (s[ODO_X], s[ODO_Y], s[ODO_T])
        robot._bumped = bool(s[BUMPED])
        robot._clearance = (s[CLEAR_X], s[CLEAR_Y], s[CLEAR_D])
        if s[UNSYNCED]:
            robot._unsynced = (s[X], s[Y], s[A], s[VX], s[VY], s[W])
        robot._drive_by_callback(bool(s[CALLBACK]))
        env.steps, env.path_length_m = int(s[STEPS]), s[PATH_M]
        env.collisions, env.k_correct, env.k_total = (
            int(s[COLLISIONS]),
            int(s[K_CORRECT]),
            int(s[K_TOTAL]),
        )
        env.steps_to = {0.5: int(s[TO_50]), 0.9: int(s[TO_90])}
        env.pose_estimate = Pose(s[EST_X], s[EST_Y], s[EST_T])
        env._squared_pose_errors, env.last_gain_bits = s[SQ_ERR], s[GAIN]
        n_rows = int(s[N_ROWS])
        for h in (env.rssi_history, env.true_path, env.odometry_trajectory, env.pose_estimates):
            h._n = n_rows
        env.mapper.n_updates = int(s[N_UPDATES])
        self.synced[i] = True

    def make_room(self, active: np.ndarray, envs: list[Any]) -> None:
        """Grow the histories of the ``active`` sub-envs that are full (before a step)."""
        for i in _short(active, self.state, self.consts, True).tolist():
            env = envs[i]
            self.sync(i, env)
            for h in (env.rssi_history, env.true_path, env.odometry_trajectory, env.pose_estimates):
                h.reserve(len(h) + 1)
            self.load(i, env)

    # ------------------------------------------------------------------ infos
    def infos(self, plan_names: np.ndarray) -> dict[str, Any]:
        """The step's info of every sub-env as `SfWExploreEnv._info` gives it (without the
        summary), batched as `sfw_gym.envs.vector.batch_infos` batches it (the ``_key`` masks
        one read-only array)."""
        n_float, n_int = len(FLOAT_INFO), len(INT_INFO)
        table = self.info_rows.T.copy()
        columns: dict[str, Any] = dict(zip(FLOAT_INFO, table[:n_float], strict=True))
        ints = table[n_float : n_float + n_int].astype(np.int64)
        columns |= dict(zip(INT_INFO, ints, strict=True))
        start = n_float + n_int
        for name in POSE_INFO:
            columns[name] = self.info_rows[:, start : start + 3].copy()
            start += 3
        columns["floorplan"] = plan_names.copy()
        every = np.ones(len(table[0]), np.bool_)
        every.flags.writeable = False
        out: dict[str, Any] = {}
        for key in self.info_order:  # a key the env added and this lacks: a KeyError here
            out[key], out[f"_{key}"] = columns[key], every
        return out
