"""Radio SLAM (the paper's first system): odometry plus radio loop closures, optimised.

:func:`radio_slam` takes a run's odometry poses and fingerprints: it fits the Eq. 3 distance
model on pairs a short drive apart (where odometry has not drifted yet), finds closure candidates
among fingerprints a long drive apart (a KD-tree), keeps those whose similarity passes a
threshold and whose similarity bin has a distance estimate, and optimises the pose graph.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from sfw_gym.core.angles import wrap_angle
from sfw_gym.core.config import Config, setting
from sfw_gym.core.errors import ConfigError
from sfw_gym.slam.fingerprints import closure_candidates, kernel_similarity
from sfw_gym.slam.pose_graph import PoseGraph, chain, relative_pose
from sfw_gym.slam.range_model import SimilarityRangeModel


@dataclass(frozen=True)
class RadioSlamConfig(Config):
    """Radio SLAM's settings (distances in metres, RSSI in dB)."""

    prefix: ClassVar[str | None] = "slam"
    sigma_db: float = setting(6.0, gt=0.0, le=50.0)  # the kernel similarity's width
    # readings weaker than this count as not heard in the similarity (None: every reading);
    # real scans carry weak, flickering and stale readings near the sensitivity floor
    min_rssi_dbm: float | None = setting(None, optional=True)
    train_travel_m: float = setting(3.0, gt=0.0)  # pairs this short a drive apart fit the model
    train_lag: int = setting(40, integer=True, ge=1)  # … at most this many poses apart
    min_travel_m: float = setting(10.0, ge=0.0)  # closures: at least this long a drive apart
    # closure candidates: fingerprints within this RMS difference per AP (the KD-tree's
    # Euclidean radius is this × √APs, so that it means the same at any AP density)
    radius_db_per_ap: float = setting(3.0, gt=0.0)
    threshold: float = setting(0.8, ge=0.0, le=1.0)  # … and at least this similar
    max_closures: int = setting(2000, integer=True, ge=1)  # an even subsample beyond this
    min_sigma_m: float = setting(0.3, gt=0.0)  # a closure's standard deviation at least
    odometry_sigma_m: float = setting(0.02, gt=0.0)  # per step
    # … plus this much per metre of each step's odometry travel, added in quadrature (odometry
    # whose error grows with the distance driven, as the robot's and the datasets' synthetic one)
    odometry_sigma_per_m: float = setting(0.0, ge=0.0)
    odometry_sigma_rad: float = setting(0.02, gt=0.0)  # per step
    robust: str = setting("cauchy", choices=("none", "huber", "cauchy"))
    robust_scale: float = setting(0.5, gt=0.0)  # the kernel's scale, in closure sigmas
    # after a first solve, closures off by more than this many sigmas are dropped and the
    # graph solved again (0: keep all)
    outlier_sigma: float = setting(3.0, ge=0.0)
    # Levenberg–Marquardt stops once a step lowers the cost by less than this fraction of it
    stop_decrease: float = setting(1e-4, gt=0.0, lt=1.0)
    keyframe_every: int = setting(5, integer=True, ge=1)  # the graph's nodes: every k-th pose
    # heading closures beside each range closure: scans taken walking (heading = the direction
    # of motion) at the same place of a rectilinear building face along the same corridor, the
    # same or the opposite way or across: the two poses' odometry turn snapped to the nearest
    # multiple of this many degrees (0: none) becomes a rotation edge …
    heading_snap_deg: float = setting(0.0, ge=0.0, le=180.0)
    heading_sigma_rad: float = setting(0.15, gt=0.0)  # … of this standard deviation …
    # … where the odometry's turn lies within this of the multiple (else no heading closure)
    heading_max_off_rad: float = setting(math.pi / 4, gt=0.0)
    # the direction snapped: 0, each pose's heading; w > 0, the odometry's direction of travel
    # from w poses before to w after (the corridor's, less the sway of single steps)
    heading_window: int = setting(0, integer=True, ge=0)
    heading_robust_scale: float = setting(0.5, gt=0.0)  # the kernel's scale on them, in sigmas
    # corridor closures beside each range closure whose two directions of travel (as above) are
    # within corridor_max_turn_rad of the same or the opposite: each pose lies on the line
    # through the other along its heading (two lateral edges), within this standard deviation
    # (0: none); the position along the corridor is left to the range edge
    corridor_sigma_m: float = setting(0.0, ge=0.0)
    corridor_max_turn_rad: float = setting(0.3, gt=0.0, le=math.pi / 2)
    corridor_robust_scale: float = setting(0.5, gt=0.0)  # the kernel's scale on them, in sigmas
    solve_every: int = setting(100, integer=True, ge=1)  # online (the env): poses between solves


@dataclass
class RadioSlamResult:
    """Corrected poses ``(N, 3)``, the closures used ``(C, 2)`` with their distance estimates
    and standard deviations."""

    poses: np.ndarray
    closures: np.ndarray
    closure_distance_m: np.ndarray
    closure_sigma_m: np.ndarray
    # the turn (rad) each closure's heading edge asked for, NaN where it had none or dropped it
    closure_turn_rad: np.ndarray | None = None
    # which closures kept a corridor closure (None where they are off)
    closure_corridor: np.ndarray | None = None


def keyframes(n: int, every: int) -> np.ndarray:
    """The pose graph's nodes among ``n`` poses: every ``every``-th pose and the last."""
    return np.unique(np.r_[np.arange(0, n, every), n - 1])


def travelled_m(odometry: np.ndarray) -> np.ndarray:
    """The odometry distance driven up to each pose ``(N,)``."""
    steps = np.linalg.norm(np.diff(odometry[:, :2], axis=0), axis=1)
    return np.r_[0.0, np.cumsum(steps)]


def fit_range_model(
    model: SimilarityRangeModel,
    odometry: np.ndarray,
    fingerprints: np.ndarray,
    config: RadioSlamConfig,
    since: int = 0,
) -> None:
    """Add to ``model`` the pairs a short drive apart (Eq. 3's training pairs) whose later pose
    is ``since`` or after: called on a growing run, each pair is added once."""
    n = len(odometry)
    along = travelled_m(odometry)
    fp = heard_readings(fingerprints, config)
    for lag in range(1, min(config.train_lag, n - 1) + 1):
        j = np.arange(max(since, lag), n)
        i = j - lag
        short = along[j] - along[i] <= config.train_travel_m
        i, j = i[short], j[short]
        d = np.linalg.norm(odometry[j, :2] - odometry[i, :2], axis=1)
        model.update(kernel_similarity(fp[i], fp[j], config.sigma_db), d)


def heard_readings(fingerprints: np.ndarray, config: RadioSlamConfig) -> np.ndarray:
    """``fingerprints`` ``(N, L)`` with the readings weaker than ``config.min_rssi_dbm`` set to
    not heard (NaN); as they are where it is None."""
    fp = np.asarray(fingerprints, np.float64)
    if config.min_rssi_dbm is None:
        return fp
    return np.where(fp >= config.min_rssi_dbm, fp, np.nan)


def radio_slam(
    odometry: np.ndarray,
    fingerprints: np.ndarray,
    config: RadioSlamConfig | None = None,
    initial: np.ndarray | None = None,
    model: SimilarityRangeModel | None = None,
    extra_closures: np.ndarray | None = None,
) -> RadioSlamResult:
    """Correct ``odometry`` ``(N, 3)`` with radio loop closures between ``fingerprints``
    ``(N, L)`` (dBm, NaN where not heard); the optimisation starts from ``initial`` ``(N, 3)``
    (default: the odometry); ``model``: an Eq. 3 model already fit on this run (default: fit
    here); ``extra_closures``: rows ``(i, j, distance_m)`` between keyframes (poses whose index
    is a multiple of ``keyframe_every``) added beside the radio ones with their median variance
    (another detector's, or false ones to test the robust kernel)."""
    cfg = config or RadioSlamConfig()
    odo = np.asarray(odometry, np.float64)
    n = len(odo)
    # The graph's nodes: every keyframe_every-th pose and the last (the poses between follow
    # their keyframe's odometry); closures between keyframes only.
    keys = keyframes(n, cfg.keyframe_every)
    pairs, mean, sigma = radio_closures(odo, fingerprints, cfg, model, extra_closures)
    node = np.full(n, -1)
    node[keys] = np.arange(len(keys))
    start = (odo if initial is None else np.asarray(initial, np.float64))[keys]
    sigma_xy = odometry_sigmas_m(odo, keys, cfg)
    direction = travel_directions(odo, cfg.heading_window)
    # the snap acts on the directions of travel; the edge asks for the headings' turn
    # that makes them a multiple apart
    course = direction[pairs[:, 1]] - direction[pairs[:, 0]]
    turn, turn_ok = snapped_turns(course, cfg)
    turn = wrap_angle(turn + odo[pairs[:, 1], 2] - odo[pairs[:, 0], 2] - course)
    parallel = np.abs(wrap_angle(2.0 * course)) <= 2.0 * cfg.corridor_max_turn_rad
    corridor = parallel & (cfg.corridor_sigma_m > 0)

    def solve(
        use: np.ndarray, start: np.ndarray, use_turn: np.ndarray, use_line: np.ndarray
    ) -> np.ndarray:
        graph = PoseGraph(len(keys), robust=cfg.robust, robust_scale=cfg.robust_scale)
        for k, (a, b) in enumerate(zip(keys[:-1].tolist(), keys[1:].tolist(), strict=True)):
            graph.add_odometry(
                k,
                k + 1,
                relative_pose(odo[a], odo[b]),
                float(sigma_xy[k]),
                cfg.odometry_sigma_rad * math.sqrt(b - a),  # independent per-step errors add up
            )
        for (i, j), m, sd in zip(
            node[pairs[use]].tolist(), mean[use].tolist(), sigma[use].tolist(), strict=True
        ):
            graph.add_range(i, j, m, sd)
        for i, j, t in zip(*node[pairs[use_turn]].T.tolist(), turn[use_turn].tolist(), strict=True):
            graph.add_rotation(i, j, t, cfg.heading_sigma_rad, cfg.heading_robust_scale)
        for i, j in node[pairs[use_line]].tolist():
            graph.add_lateral(i, j, 0.0, cfg.corridor_sigma_m, cfg.corridor_robust_scale)
            graph.add_lateral(j, i, 0.0, cfg.corridor_sigma_m, cfg.corridor_robust_scale)
        return graph.optimize(start, relative_decrease=cfg.stop_decrease)

    use = np.ones(len(pairs), bool)
    use_turn, use_line = turn_ok.copy(), corridor.copy()
    solved = solve(use, start, use_turn, use_line)
    if cfg.outlier_sigma and len(pairs):  # drop the closures the solution disagrees with
        ends = solved[node[pairs]]
        use = consistent_closures(ends, mean, sigma, cfg.outlier_sigma)
        off = np.abs(wrap_angle(ends[:, 1, 2] - ends[:, 0, 2] - turn))
        use_turn = turn_ok & use & (off <= cfg.outlier_sigma * cfg.heading_sigma_rad)
        lateral = np.maximum(
            lateral_offsets(ends[:, 0], ends[:, 1]), lateral_offsets(ends[:, 1], ends[:, 0])
        )
        use_line = corridor & use & (lateral <= cfg.outlier_sigma * cfg.corridor_sigma_m)
        if not (use.all() and (use_turn == turn_ok).all() and (use_line == corridor).all()):
            solved = solve(use, solved, use_turn, use_line)
    anchor = keys[np.searchsorted(keys, np.arange(n), side="right") - 1]
    poses = chain(solved[node[anchor]], odo[anchor], odo)
    turns = np.where(use_turn, turn, np.nan)[use] if cfg.heading_snap_deg else None
    lines = use_line[use] if cfg.corridor_sigma_m else None
    return RadioSlamResult(poses, pairs[use], mean[use], sigma[use], turns, lines)


def lateral_offsets(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """How far poses ``b`` ``(C, 3)`` lie off the lines through poses ``a`` along their headings
    (m, unsigned)."""
    c, s = np.cos(a[:, 2]), np.sin(a[:, 2])
    d = b[:, :2] - a[:, :2]
    return np.abs(-s * d[:, 0] + c * d[:, 1])


def travel_directions(odometry: np.ndarray, window: int) -> np.ndarray:
    """Each pose's direction of travel ``(N,)`` (rad): its heading where ``window`` is 0, else
    the direction of the odometry's displacement from ``window`` poses before it to ``window``
    after (clipped at the ends; the heading where that displacement is under 1 cm)."""
    odo = np.asarray(odometry, np.float64)
    if not window:
        return odo[:, 2].copy()
    k = np.arange(len(odo))
    d = odo[np.minimum(k + window, len(odo) - 1), :2] - odo[np.maximum(k - window, 0), :2]
    moved = np.hypot(d[:, 0], d[:, 1]) >= 0.01
    return np.where(moved, np.arctan2(d[:, 1], d[:, 0]), odo[:, 2])


def snapped_turns(
    odometry_turn: np.ndarray, config: RadioSlamConfig
) -> tuple[np.ndarray, np.ndarray]:
    """Heading closures: each odometry turn ``(C,)`` (rad) snapped to the nearest multiple of
    ``config.heading_snap_deg``, and whether to use it (the snap is on, and the turn lies within
    ``config.heading_max_off_rad`` of that multiple)."""
    raw = wrap_angle(np.asarray(odometry_turn, np.float64))
    if not config.heading_snap_deg:
        return raw, np.zeros(raw.shape, bool)
    unit = math.radians(config.heading_snap_deg)
    turn = wrap_angle(np.round(raw / unit) * unit)
    return turn, np.abs(wrap_angle(raw - turn)) <= config.heading_max_off_rad


def odometry_sigmas_m(
    odometry: np.ndarray, keys: np.ndarray, config: RadioSlamConfig
) -> np.ndarray:
    """The translation standard deviation (m) of each odometry edge between consecutive
    ``keys``: ``odometry_sigma_m`` per step and ``odometry_sigma_per_m`` per metre of each
    step's travel, independent per step (their variances add up)."""
    step = np.linalg.norm(np.diff(odometry[:, :2], axis=0), axis=1)
    per_step = config.odometry_sigma_m**2 + (config.odometry_sigma_per_m * step) ** 2
    var = np.r_[0.0, np.cumsum(per_step)]
    return np.sqrt(np.diff(var[keys]))


def consistent_closures(
    ends: np.ndarray, distance_m: np.ndarray, sigma_m: np.ndarray, outlier_sigma: float
) -> np.ndarray:
    """Which range closures a solution agrees with: its poses ``ends`` ``(C, 2, 3)`` lie within
    ``outlier_sigma`` standard deviations of each closure's distance."""
    apart = np.linalg.norm(ends[:, 1, :2] - ends[:, 0, :2], axis=1)
    return np.abs(apart - distance_m) <= outlier_sigma * sigma_m


def radio_closures(
    odometry: np.ndarray,
    fingerprints: np.ndarray,
    config: RadioSlamConfig | None = None,
    model: SimilarityRangeModel | None = None,
    extra_closures: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Radio loop closures between keyframes: pose pairs ``(C, 2)``, their distance estimates
    and standard deviations (m); the arguments as :func:`radio_slam`'s."""
    cfg = config or RadioSlamConfig()
    odo = np.asarray(odometry, np.float64)
    fp = heard_readings(fingerprints, cfg)
    travelled = travelled_m(odo)
    if model is None:
        model = SimilarityRangeModel()
        fit_range_model(model, odo, fp, cfg)
    keys = keyframes(len(odo), cfg.keyframe_every)
    pairs = keys[
        closure_candidates(
            fp[keys],
            travelled[keys],
            min_travel_m=cfg.min_travel_m,
            radius_db=cfg.radius_db_per_ap * math.sqrt(fp.shape[1]),
        )
    ].reshape(-1, 2)
    similarity = kernel_similarity(fp[pairs[:, 0]], fp[pairs[:, 1]], cfg.sigma_db)
    mean, var = model.predict(similarity)
    keep = (similarity >= cfg.threshold) & np.isfinite(mean)
    pairs, mean, var = pairs[keep], mean[keep], var[keep]
    if len(pairs) > cfg.max_closures:
        pick = np.linspace(0, len(pairs) - 1, cfg.max_closures).astype(int)
        pairs, mean, var = pairs[pick], mean[pick], var[pick]
    if extra_closures is not None:
        extra = np.asarray(extra_closures, np.float64).reshape(-1, 3)
        ends = extra[:, :2].astype(np.int64)
        if not np.isin(ends, keys).all():
            raise ConfigError("extra_closures must join keyframes (indices k * keyframe_every)")
        typical = float(np.median(var)) if len(var) else 0.0  # as sure as a radio closure
        pairs = np.concatenate([pairs, ends])
        mean = np.concatenate([mean, extra[:, 2]])
        var = np.concatenate([var, np.full(len(extra), typical)])
    return pairs, mean, np.maximum(np.sqrt(var), cfg.min_sigma_m)
