"""Radio+LiDAR SLAM (the Radio SLAM paper's second system) and a LiDAR-only baseline.

:func:`lidar_slam` takes a run's odometry, LiDAR scans (points in the robot's frame, at least at
every keyframe) and, for Radio+LiDAR, fingerprints:

1. consecutive keyframes' scans registered by ICP from the odometry's guess (short-term
   drift; the odometry where ICP fails);
2. first trajectory — these registrations chained, with Radio SLAM's loop closures
   (:func:`~sfw_gym.slam.radio_slam.radio_closures`) solved in; without radio (the baseline),
   the registrations chained;
3. LiDAR loop closures: keyframe pairs a long drive apart that the current trajectory puts
   within ``closure_radius_m``, registered by ICP from that trajectory's guess, kept when the
   paper's rule accepts the match (fitness < 0.1 m², more than half the points matched; and
   walls in two directions, :class:`~sfw_gym.slam.scan_matching.IcpResult`);
4. the pose graph solved again with the radio closures, the scan edges and the LiDAR closures;
   closures the solution disagrees with dropped, steps 3–4 repeated ``rounds`` times.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from scipy.spatial import cKDTree

from sfw_gym.core.config import Config, setting
from sfw_gym.core.errors import ConfigError
from sfw_gym.slam.pose_graph import PoseGraph, chain, compose_pose, relative_pose
from sfw_gym.slam.radio_slam import (
    RadioSlamConfig,
    consistent_closures,
    keyframes,
    radio_closures,
    travelled_m,
)
from sfw_gym.slam.range_model import SimilarityRangeModel
from sfw_gym.slam.scan_matching import IcpConfig, IcpResult, icp


@dataclass(frozen=True)
class LidarSlamConfig(Config):
    """The LiDAR stage's settings (metres, radians)."""

    prefix: ClassVar[str | None] = "lidar_slam"
    closure_radius_m: float = setting(1.5, gt=0.0)  # pairs this close on the trajectory
    min_travel_m: float = setting(5.0, ge=0.0)  # … and at least this long a drive apart
    max_closures: int = setting(400, integer=True, ge=1)  # ICP tries per round, spread evenly
    scan_sigma_m: float = setting(0.05, gt=0.0)  # an accepted ICP edge's standard deviation
    scan_sigma_rad: float = setting(0.01, gt=0.0)
    # a consecutive registration of a weakly constrained scan pair (observability below
    # well_constrained: a corridor seen over a few metres) is used only within this many
    # standard deviations of the odometry's step: one that slid along the corridor is worse
    # than the odometry it would replace
    step_gate_sigma: float = setting(3.0, gt=0.0)
    well_constrained: float = setting(0.1, ge=0.0, le=0.5)
    outlier_m: float = setting(0.3, gt=0.0)  # closures the solution misses by more: dropped
    rounds: int = setting(2, integer=True, ge=1)  # closure search → solve, repeated
    # LiDAR loop closures must also pass these (the paper's 0.1 m² and one half, for real
    # scans, let ~5 % false closures through on the simulator's, whose true matches stay
    # below 0.01 m²; 0.1 and 0.5 give the paper's rule alone)
    closure_max_fitness: float = setting(0.01, gt=0.0)
    closure_min_match_fraction: float = setting(0.8, ge=0.0, le=1.0)
    # keep the radio closures in the second optimisation (the paper: Eq. 1 again, with the
    # LiDAR constraints added)
    radio_in_final: bool = setting(True, choices=(True, False))


@dataclass
class LidarSlamResult:
    """Corrected poses ``(N, 3)``; the accepted LiDAR closures ``(C, 2)`` (pose indices); the
    fraction of consecutive keyframe pairs that ICP registered; the ICP calls made."""

    poses: np.ndarray
    lidar_closures: np.ndarray
    consecutive_registered: float
    icp_calls: int


def lidar_slam(
    odometry: np.ndarray,
    scans: Mapping[int, np.ndarray],
    fingerprints: np.ndarray | None = None,
    *,
    radio: RadioSlamConfig | None = None,
    config: LidarSlamConfig | None = None,
    icp_config: IcpConfig | None = None,
    initial: np.ndarray | None = None,
    model: SimilarityRangeModel | None = None,
    cache: dict[tuple[int, int], IcpResult] | None = None,
) -> LidarSlamResult:
    """Radio+LiDAR SLAM (with ``fingerprints``) or LiDAR-only SLAM (without) on a run.

    ``odometry`` ``(N, 3)``; ``scans``: pose index → points ``(M, 2)`` in that pose's robot frame,
    for every keyframe (every ``radio.keyframe_every``-th pose and the last); ``initial``: a
    starting trajectory for the radio stage; ``model``: Radio SLAM's Eq. 3 model fit on this run;
    ``cache``: consecutive registrations by pose pair, kept between calls on a growing run.
    """
    rcfg = radio or RadioSlamConfig()
    cfg = config or LidarSlamConfig()
    icfg = icp_config or IcpConfig()
    odo = np.asarray(odometry, np.float64)
    n = len(odo)
    keys = keyframes(n, rcfg.keyframe_every)
    missing = [int(k) for k in keys if int(k) not in scans]
    if missing:
        raise ConfigError(f"lidar_slam: no scan for keyframe pose(s) {missing[:5]}")
    cache = {} if cache is None else cache
    calls = 0

    def register(i: int, j: int, guess: tuple[float, float, float]) -> IcpResult:
        nonlocal calls
        calls += 1
        return icp(scans[i], scans[j], guess, icfg)

    # consecutive keyframes: ICP from the odometry's guess, odometry where ICP fails
    steps: list[tuple[tuple[float, float, float], float, float]] = []
    registered = 0
    for a, b in zip(keys[:-1].tolist(), keys[1:].tolist(), strict=True):
        guess = relative_pose(odo[a], odo[b])
        if (a, b) not in cache:
            cache[(a, b)] = register(a, b, guess)
        result = cache[(a, b)]
        spread = math.sqrt(b - a)  # independent per-step errors add up
        sigma_xy, sigma_theta = rcfg.odometry_sigma_m * spread, rcfg.odometry_sigma_rad * spread
        gate_xy = cfg.step_gate_sigma * math.hypot(sigma_xy, cfg.scan_sigma_m)
        gate_theta = cfg.step_gate_sigma * math.hypot(sigma_theta, cfg.scan_sigma_rad)
        off = np.asarray(result.delta) - guess
        near = (
            math.hypot(off[0], off[1]) <= gate_xy
            and abs(math.remainder(off[2], 2 * math.pi)) <= gate_theta
        )
        if result.accepted(len(scans[a]), len(scans[b]), icfg) and (
            near or result.observability >= cfg.well_constrained
        ):
            registered += 1
            steps.append((tuple(result.delta), cfg.scan_sigma_m, cfg.scan_sigma_rad))
        else:
            steps.append((guess, sigma_xy, sigma_theta))

    # first trajectory: the scan-matched odometry, with radio closures solved in (Radio SLAM
    # on the registered scans), closures the solution disagrees with dropped
    estimate = np.empty((len(keys), 3))
    estimate[0] = odo[0]
    for m, (delta, _, _) in enumerate(steps):
        estimate[m + 1] = compose_pose(estimate[m], delta)
    matched = estimate.copy()
    ranges = np.zeros((0, 4))  # radio closures: node i, node j, distance, sigma
    if fingerprints is not None:
        pairs, distance, sigma = radio_closures(odo, fingerprints, rcfg, model)
        ranges = np.column_stack([np.searchsorted(keys, pairs), distance, sigma])
        if initial is not None:  # a previous solution (online): start from it
            estimate = np.asarray(initial, np.float64)[keys]
        estimate = _solve(estimate, steps, ranges, {}, rcfg, cfg)
        if rcfg.outlier_sigma and len(ranges):
            nodes = ranges[:, :2].astype(np.int64)
            ranges = ranges[
                consistent_closures(estimate[nodes], ranges[:, 2], ranges[:, 3], rcfg.outlier_sigma)
            ]
            estimate = _solve(estimate, steps, ranges, {}, rcfg, cfg)

    along = travelled_m(odo)[keys]
    closures: dict[tuple[int, int], IcpResult] = {}
    if not cfg.radio_in_final:
        ranges = ranges[:0]
    for round_ in range(cfg.rounds):
        candidates = [(pair, estimate) for pair in _closure_candidates(estimate, along, cfg)]
        if round_ == 0 and fingerprints is not None:  # where the scans alone would look too
            candidates += [(pair, matched) for pair in _closure_candidates(matched, along, cfg)]
        for pair, guide in candidates:
            if pair in closures:
                continue
            i, j = pair
            result = register(int(keys[i]), int(keys[j]), relative_pose(guide[i], guide[j]))
            n_a, n_b = len(scans[int(keys[i])]), len(scans[int(keys[j])])
            if (
                result.accepted(n_a, n_b, icfg)
                and result.fitness < cfg.closure_max_fitness
                and result.matched > cfg.closure_min_match_fraction * (n_a + n_b) / 2
            ):
                closures[pair] = result
        # the first solve starts from the registered scans chained: locally right everywhere,
        # where a first stage bent by false radio closures may hold the solver in a wrong basin
        estimate = _solve(matched if round_ == 0 else estimate, steps, ranges, closures, rcfg, cfg)
        for _ in range(3):  # drop the closures the solution disagrees with, solve again
            missed = [p for p, r in closures.items() if _missed_by(estimate, p, r) > cfg.outlier_m]
            for pair in missed:
                del closures[pair]
            agree = np.ones(len(ranges), bool)
            if rcfg.outlier_sigma and len(ranges):
                nodes = ranges[:, :2].astype(np.int64)
                agree = consistent_closures(
                    estimate[nodes], ranges[:, 2], ranges[:, 3], rcfg.outlier_sigma
                )
                ranges = ranges[agree]
            if not missed and agree.all():
                break
            estimate = _solve(estimate, steps, ranges, closures, rcfg, cfg)
    anchor = keys[np.searchsorted(keys, np.arange(n), side="right") - 1]
    node_of = np.full(n, -1)
    node_of[keys] = np.arange(len(keys))
    poses = chain(estimate[node_of[anchor]], odo[anchor], odo)
    pairs = np.array([(keys[i], keys[j]) for i, j in closures], np.int64).reshape(-1, 2)
    return LidarSlamResult(poses, pairs, registered / max(1, len(steps)), calls)


def _closure_candidates(
    estimate: np.ndarray, along: np.ndarray, cfg: LidarSlamConfig
) -> list[tuple[int, int]]:
    """Keyframe pairs within ``closure_radius_m`` on ``estimate`` and a long drive apart, at
    most ``max_closures`` spread evenly over the list."""
    pairs = cKDTree(estimate[:, :2]).query_pairs(cfg.closure_radius_m, output_type="ndarray")
    pairs = pairs[np.abs(along[pairs[:, 1]] - along[pairs[:, 0]]) >= cfg.min_travel_m]
    if len(pairs) > cfg.max_closures:
        pairs = pairs[np.linspace(0, len(pairs) - 1, cfg.max_closures).astype(int)]
    return [(int(i), int(j)) for i, j in pairs]


def _missed_by(estimate: np.ndarray, pair: tuple[int, int], result: IcpResult) -> float:
    """How far (m) the solution puts pose ``j`` from where the closure says it is."""
    i, j = pair
    return float(np.hypot(*(compose_pose(estimate[i], tuple(result.delta))[:2] - estimate[j, :2])))


def _solve(
    start: np.ndarray,
    steps: list[tuple[tuple[float, float, float], float, float]],
    ranges: np.ndarray,
    closures: dict[tuple[int, int], IcpResult],
    rcfg: RadioSlamConfig,
    cfg: LidarSlamConfig,
) -> np.ndarray:
    graph = PoseGraph(len(start), robust=rcfg.robust, robust_scale=rcfg.robust_scale)
    for m, (delta, sigma_xy, sigma_theta) in enumerate(steps):
        graph.add_odometry(m, m + 1, delta, sigma_xy, sigma_theta)
    for i, j, d, sigma in ranges.tolist():
        graph.add_range(int(i), int(j), d, sigma)
    for (i, j), result in closures.items():
        graph.add_odometry(i, j, tuple(result.delta), cfg.scan_sigma_m, cfg.scan_sigma_rad)
    return graph.optimize(start, relative_decrease=rcfg.stop_decrease)
