"""ICP scan matching of 2-D LiDAR scans (the Radio+LiDAR SLAM paper's registration step).

:func:`icp` registers scan B onto scan A (points in each robot's frame) from an initial guess
(odometry): nearest neighbours in a KD-tree of A, pairs beyond ``max_correspondence_m`` rejected,
then a closed-form rigid alignment (point-to-point) or a Gauss–Newton step on the distances to
A's local lines (point-to-line), repeated until the step is below ``tolerance``.
:meth:`IcpResult.accepted` is the paper's acceptance rule (fitness < 0.1 m² and more than half
the two scans' average point count matched), plus a guard against degenerate geometry (a
corridor, where the translation along the walls is unobserved).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from scipy.spatial import cKDTree

from sfw_gym.core.angles import wrap_angle
from sfw_gym.core.config import Config, brief_repr, float_array, setting
from sfw_gym.core.errors import ConfigError

# a point of A's normal: PCA of its 5 nearest points (itself included), or of up to 16 within
# 0.15 m where more
NORMAL_MIN_NEIGHBOURS = 5
NORMAL_MAX_NEIGHBOURS = 16
NORMAL_RADIUS_M = 0.15


@dataclass(frozen=True)
class IcpConfig(Config):
    """ICP's settings (metres, radians)."""

    prefix: ClassVar[str | None] = "icp"
    max_iterations: int = setting(30, integer=True, ge=1)
    max_correspondence_m: float = setting(0.5, gt=0.0)  # pairs farther apart are rejected
    tolerance: float = setting(1e-5, gt=0.0)  # stop once a step moves less (m and rad)
    method: str = setting("point_to_line", choices=("point_to_line", "point_to_point"))
    max_fitness: float = setting(0.1, gt=0.0)  # accepted: fitness (m²) below this …
    min_match_fraction: float = setting(0.5, ge=0.0, le=1.0)  # … and more matched than this
    # … of the two scans' mean point count, and min_observability (see IcpResult) at least this
    # (0: the paper's rule alone)
    min_observability: float = setting(0.02, ge=0.0, le=0.5)


@dataclass
class IcpResult:
    """One registration.

    ``delta``: ``(dx, dy, dθ)`` ``(3,)``, scan B's frame seen from scan A's (as
    :func:`~sfw_gym.slam.pose_graph.relative_pose`: ``compose_pose(pose_a, delta)`` is pose B);
    the initial guess where ICP failed. ``fitness``: the matched pairs' mean squared distance
    (m², PCL's fitness score; inf where fewer than 3 pairs). ``matched``: B's points within
    ``max_correspondence_m`` of A at the end. ``observability``: the smallest eigenvalue of the
    mean ``n nᵀ`` over the matched pairs' normals (0 when all walls are parallel, so that the
    translation along them is unobserved; at most 0.5). ``converged``: the last step was below
    the tolerance.
    """

    delta: np.ndarray
    fitness: float
    matched: int
    iterations: int
    converged: bool
    observability: float

    def accepted(self, n_a: int, n_b: int, config: IcpConfig | None = None) -> bool:
        """The paper's valid match for scans of ``n_a`` and ``n_b`` points: fitness below
        ``max_fitness`` and more than ``min_match_fraction`` of their mean point count matched;
        also observability at least ``min_observability``."""
        cfg = config or IcpConfig()
        return (
            self.fitness < cfg.max_fitness
            and self.matched > cfg.min_match_fraction * 0.5 * (n_a + n_b)
            and self.observability >= cfg.min_observability
        )


def _points(name: str, value: object) -> np.ndarray:
    points = float_array(name, value)
    if points.size == 0:
        return np.zeros((0, 2))
    if points.ndim != 2 or points.shape[1] != 2:
        raise ConfigError(f"icp: {name} must be an (N, 2) array, got shape {points.shape}")
    if not np.isfinite(points).all():
        raise ConfigError(f"icp: {name} has NaN or infinite coordinates")
    return points


def _normals(tree: cKDTree, points: np.ndarray) -> np.ndarray:
    """Unit normals ``(N, 2)``: the least-spread direction (PCA) of each point's
    ``NORMAL_MIN_NEIGHBOURS`` nearest points, or of those within ``NORMAL_RADIUS_M`` (at most
    ``NORMAL_MAX_NEIGHBOURS``) where more (so that noise on densely sampled walls near the
    sensor does not tilt them)."""
    k = min(NORMAL_MAX_NEIGHBOURS, len(points))
    dist, idx = tree.query(points, k=k)
    w = dist <= NORMAL_RADIUS_M
    w[:, :NORMAL_MIN_NEIGHBOURS] = True
    x = (points[:, 0][idx] - points[:, :1]) * w  # relative to the point itself
    y = (points[:, 1][idx] - points[:, 1:]) * w
    count, sx, sy = w.sum(1), x.sum(1), y.sum(1)
    cxx = (x * x).sum(1) - sx * sx / count
    cyy = (y * y).sum(1) - sy * sy / count
    cxy = (x * y).sum(1) - sx * sy / count
    along = 0.5 * np.arctan2(2.0 * cxy, cxx - cyy)  # the principal axis
    return np.column_stack([-np.sin(along), np.cos(along)])


def _observability(normals: np.ndarray) -> float:
    """Smallest eigenvalue of the mean ``n nᵀ`` of unit ``normals``."""
    a, c = (normals[:, 0] ** 2).mean(), (normals[:, 1] ** 2).mean()
    b = (normals[:, 0] * normals[:, 1]).mean()
    return float(max(0.0, 0.5 * (a + c) - math.hypot(0.5 * (a - c), b)))


def _step_point_to_point(p: np.ndarray, q: np.ndarray) -> tuple[float, float, float]:
    """The rigid motion ``(tx, ty, θ)`` that best maps ``p`` onto ``q`` (closed form, 2-D
    Umeyama)."""
    pm, qm = p.mean(0), q.mean(0)
    pc, qc = p - pm, q - qm
    theta = math.atan2(
        float((pc[:, 0] * qc[:, 1] - pc[:, 1] * qc[:, 0]).sum()), float((pc * qc).sum())
    )
    c, s = math.cos(theta), math.sin(theta)
    return qm[0] - (c * pm[0] - s * pm[1]), qm[1] - (s * pm[0] + c * pm[1]), theta


def _step_point_to_line(p: np.ndarray, q: np.ndarray, n: np.ndarray) -> tuple[float, float, float]:
    """One Gauss–Newton step ``(tx, ty, θ)`` on the distances ``n·(p - q)`` of ``p`` to the
    lines through ``q`` with normals ``n`` (least norm along unobserved directions)."""
    jac = np.column_stack([n, n[:, 1] * p[:, 0] - n[:, 0] * p[:, 1]])
    r = ((p - q) * n).sum(1)
    step = np.linalg.lstsq(jac.T @ jac, -(jac.T @ r), rcond=1e-10)[0]
    return float(step[0]), float(step[1]), float(step[2])


def _transform(points: np.ndarray, pose: tuple[float, float, float]) -> np.ndarray:
    c, s = math.cos(pose[2]), math.sin(pose[2])
    return points @ np.array([[c, s], [-s, c]]) + np.array(pose[:2])


def icp(
    points_a: np.ndarray,
    points_b: np.ndarray,
    initial: tuple[float, float, float] | np.ndarray = (0.0, 0.0, 0.0),
    config: IcpConfig | None = None,
) -> IcpResult:
    """Register scan B (``points_b`` ``(M, 2)`` in B's robot frame) onto scan A (``points_a``
    ``(N, 2)`` in A's) from ``initial`` ``(dx, dy, dθ)``, B's frame seen from A's (odometry's
    :func:`~sfw_gym.slam.pose_graph.relative_pose`). Fewer than 3 points in either scan, or
    fewer than 3 pairs at some iteration: not converged, fitness inf, ``delta`` the initial
    guess. A NaN or infinite coordinate: :class:`ConfigError`."""
    cfg = config or IcpConfig()
    a, b = _points("points_a", points_a), _points("points_b", points_b)
    guess = float_array("initial", initial).ravel()
    if guess.shape != (3,) or not np.isfinite(guess).all():
        raise ConfigError(
            f"icp: initial must be 3 finite numbers (dx, dy, dθ), got {brief_repr(initial)}"
        )
    x, y, th = map(float, guess)

    def failed(matched: int, iterations: int) -> IcpResult:
        return IcpResult(guess.copy(), math.inf, matched, iterations, False, 0.0)

    if len(a) == 0 or len(b) == 0:
        return failed(0, 0)
    tree = cKDTree(a)
    radius = cfg.max_correspondence_m

    def pairs(pose: tuple[float, float, float]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        p = _transform(b, pose)
        dist, idx = tree.query(p, distance_upper_bound=radius)
        ok = np.isfinite(dist)
        return p[ok], idx[ok], dist[ok]

    if len(a) < 3 or len(b) < 3:
        return failed(len(pairs((x, y, th))[0]), 0)
    normals = _normals(tree, a)
    converged = False
    iterations = 0
    while iterations < cfg.max_iterations and not converged:
        iterations += 1
        p, idx, _ = pairs((x, y, th))
        if len(p) < 3:
            return failed(len(p), iterations)
        if cfg.method == "point_to_point":
            tx, ty, dth = _step_point_to_point(p, a[idx])
        else:
            tx, ty, dth = _step_point_to_line(p, a[idx], normals[idx])
        c, s = math.cos(dth), math.sin(dth)
        x, y, th = c * x - s * y + tx, s * x + c * y + ty, th + dth
        converged = math.hypot(tx, ty) < cfg.tolerance and abs(dth) < cfg.tolerance
    th = wrap_angle(th)
    p, idx, dist = pairs((x, y, th))
    if len(p) < 3:
        return failed(len(p), iterations)
    return IcpResult(
        np.array([x, y, th]),
        float((dist**2).mean()),
        len(p),
        iterations,
        converged,
        _observability(normals[idx]),
    )
