"""Trajectory error: ATE and RPE (evo's definitions for SE(2); evo itself is GPL)."""

from __future__ import annotations

import numpy as np

from sfw_gym.core.angles import wrap_angle
from sfw_gym.core.errors import ConfigError


def _pair(estimate: np.ndarray, truth: np.ndarray, columns: int) -> tuple[np.ndarray, np.ndarray]:
    p = np.asarray(estimate, np.float64)
    q = np.asarray(truth, np.float64)
    if p.ndim != 2 or q.ndim != 2 or len(p) != len(q) or len(p) == 0:
        raise ConfigError(f"trajectories must have the same N rows, got {p.shape}, {q.shape}")
    if min(p.shape[1], q.shape[1]) < columns:
        raise ConfigError(
            f"trajectories must have the same (N, {columns}+) shape, got {p.shape}, {q.shape}"
        )
    return p[:, :columns], q[:, :columns]


def absolute_trajectory_error(estimate: np.ndarray, truth: np.ndarray, align: bool = True) -> float:
    """RMSE (m) of the estimated positions against the true ones ``(N, 2+)``; with ``align``
    after the rigid 2-D motion that best aligns them (Kabsch / Umeyama without scale), without
    it as they are (a run whose estimate starts at the true pose shares the truth's frame)."""
    p, q = _pair(estimate, truth, 2)
    if align:
        mp, mq = p.mean(0), q.mean(0)
        u, _, vt = np.linalg.svd((p - mp).T @ (q - mq))
        if np.linalg.det(u @ vt) < 0:  # a reflection: flip the smaller axis
            vt[-1] *= -1
        p = (p - mp) @ (u @ vt) + mq
    return float(np.sqrt(np.mean(np.sum((p - q) ** 2, axis=1))))


def relative_pose_error(
    estimate: np.ndarray, truth: np.ndarray, delta: int = 1
) -> tuple[float, float]:
    """RMSE of the motion between poses ``delta`` apart ``(N, 3)``: translation (m) and
    rotation (rad) of ``(truth_i⁻¹ truth_j)⁻¹ (estimate_i⁻¹ estimate_j)`` (drift per ``delta``)."""
    p, q = _pair(estimate, truth, 3)
    if isinstance(delta, bool) or not isinstance(delta, int) or not 1 <= delta < len(p):
        raise ConfigError(f"delta must be an integer in [1, {len(p) - 1}], got {delta!r}")

    def motion(x: np.ndarray) -> np.ndarray:
        d = x[delta:, :2] - x[:-delta, :2]
        c, s = np.cos(x[:-delta, 2]), np.sin(x[:-delta, 2])
        turn = x[delta:, 2] - x[:-delta, 2]
        return np.column_stack([c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1], turn])

    me, mt = motion(p), motion(q)
    c, s = np.cos(mt[:, 2]), np.sin(mt[:, 2])
    dx, dy = me[:, 0] - mt[:, 0], me[:, 1] - mt[:, 1]
    ex, ey = c * dx + s * dy, -s * dx + c * dy  # in the true end frame
    rot = wrap_angle(me[:, 2] - mt[:, 2])
    return float(np.sqrt(np.mean(ex**2 + ey**2))), float(np.sqrt(np.mean(rot**2)))
