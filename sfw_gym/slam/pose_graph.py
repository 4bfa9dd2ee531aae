"""An SE(2) pose graph (the paper's Eq. 1): odometry edges (relative poses), range edges
(radio loop closures: a distance and its variance), and rotation and lateral edges (a closure's
turn; a pose on the line along another's heading), optimised by a sparse Levenberg–Marquardt
with a robust kernel on the closure edges (iteratively reweighted), so that a false closure pulls
with a bounded force instead of bending the trajectory."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve

from sfw_gym.core.angles import wrap_angle
from sfw_gym.core.errors import ConfigError

ROBUST_KERNELS = ("none", "huber", "cauchy")


def relative_pose(a: np.ndarray, b: np.ndarray) -> tuple[float, float, float]:
    """Pose ``b`` seen from pose ``a``: ``(dx, dy, dθ)`` in ``a``'s frame (an odometry edge)."""
    c, s = math.cos(a[2]), math.sin(a[2])
    dx, dy = b[0] - a[0], b[1] - a[1]
    return c * dx + s * dy, -s * dx + c * dy, float(wrap_angle(b[2] - a[2]))


def compose_pose(a: np.ndarray, delta: tuple[float, float, float]) -> np.ndarray:
    """The pose ``delta`` (in ``a``'s frame) leads to from ``a``: the inverse of
    :func:`relative_pose`."""
    c, s = math.cos(a[2]), math.sin(a[2])
    dx, dy, dth = delta
    return np.array([a[0] + c * dx - s * dy, a[1] + s * dx + c * dy, a[2] + dth])


def chain(anchor_estimate: np.ndarray, anchor_odometry: np.ndarray, odometry: np.ndarray):
    """Poses ``(K, 3)`` that follow ``anchor_estimate`` as ``odometry`` ``(K, 3)`` follows
    ``anchor_odometry`` (each ``(3,)``, or ``(K, 3)``: one anchor per pose): the odometry
    increments since the anchor, applied to its estimate."""
    anchor_estimate = np.asarray(anchor_estimate, np.float64)
    anchor_odometry = np.asarray(anchor_odometry, np.float64)
    d = odometry[:, :2] - anchor_odometry[..., :2]
    turn = anchor_estimate[..., 2] - anchor_odometry[..., 2]
    c, s = np.cos(turn), np.sin(turn)
    out = np.empty_like(odometry)
    out[:, 0] = anchor_estimate[..., 0] + c * d[:, 0] - s * d[:, 1]
    out[:, 1] = anchor_estimate[..., 1] + s * d[:, 0] + c * d[:, 1]
    out[:, 2] = wrap_angle(odometry[:, 2] + turn)
    return out


@dataclass
class PoseGraph:
    """Edges between poses ``0 … n_poses-1``; :meth:`optimize` moves the poses.

    Args:
        n_poses: Number of poses.
        robust: Kernel on the range edges: ``"huber"``, ``"cauchy"`` or ``"none"``.
        robust_scale: The kernel's scale, in standard deviations of a range edge.
    """

    n_poses: int
    robust: str = "cauchy"
    robust_scale: float = 2.0
    _odo: list[tuple[float, ...]] = field(default_factory=list)
    _rng: list[tuple[float, ...]] = field(default_factory=list)
    _rot: list[tuple[float, ...]] = field(default_factory=list)
    _lat: list[tuple[float, ...]] = field(default_factory=list)

    def __post_init__(self) -> None:
        if self.robust not in ROBUST_KERNELS:
            raise ConfigError(f"robust must be one of {ROBUST_KERNELS}, got {self.robust!r}")
        if self.n_poses < 1:
            raise ConfigError(f"n_poses must be >= 1, got {self.n_poses!r}")

    def add_odometry(
        self, i: int, j: int, delta: tuple[float, float, float], sigma_xy: float, sigma_theta: float
    ) -> None:
        """Pose ``j`` seen from pose ``i``: ``delta = (dx, dy, dθ)`` in ``i``'s frame."""
        self._odo.append(
            (float(i), float(j), *map(float, delta), float(sigma_xy), float(sigma_theta))
        )

    def add_range(self, i: int, j: int, distance_m: float, sigma_m: float) -> None:
        """Poses ``i`` and ``j`` lie ``distance_m`` apart (a radio loop closure)."""
        if not sigma_m > 0:
            raise ConfigError(f"range edge ({i}, {j}): sigma_m must be > 0, got {sigma_m!r}")
        self._rng.append((float(i), float(j), float(distance_m), float(sigma_m)))

    def add_rotation(
        self, i: int, j: int, dtheta: float, sigma_rad: float, robust_scale: float | None = None
    ) -> None:
        """Pose ``j``'s heading is pose ``i``'s plus ``dtheta`` (a heading closure), under the
        robust kernel at ``robust_scale`` of its sigmas (None: the graph's)."""
        if not sigma_rad > 0:
            raise ConfigError(f"rotation edge ({i}, {j}): sigma_rad must be > 0, got {sigma_rad!r}")
        scale = self.robust_scale if robust_scale is None else robust_scale
        self._rot.append((float(i), float(j), float(dtheta), float(sigma_rad), float(scale)))

    def add_lateral(
        self, i: int, j: int, offset_m: float, sigma_m: float, robust_scale: float | None = None
    ) -> None:
        """Pose ``j`` lies ``offset_m`` to the left of the line through pose ``i`` along its
        heading (a corridor closure: 0 where both walk the same corridor; the position along it
        is left free), under the robust kernel at ``robust_scale`` of its sigmas (None: the
        graph's)."""
        if not sigma_m > 0:
            raise ConfigError(f"lateral edge ({i}, {j}): sigma_m must be > 0, got {sigma_m!r}")
        scale = self.robust_scale if robust_scale is None else robust_scale
        self._lat.append((float(i), float(j), float(offset_m), float(sigma_m), float(scale)))

    # -- the least-squares problem ----------------------------------------------------------------
    def _linearize(
        self,
        x: np.ndarray,
        anchor: np.ndarray,
        robust_weights: np.ndarray | None,
        edges: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    ) -> tuple[np.ndarray, sp.csr_matrix, np.ndarray]:
        """Whitened residuals, their sparse Jacobian, and the range, rotation then lateral
        edges' whitened errors (``robust_weights``: one per such edge, in that order)."""
        odo, rng, rot, lat = edges
        # the first pose is held where it starts (the gauge)
        prior_w = 1e6
        res = [prior_w * np.r_[x[0, :2] - anchor[:2], wrap_angle(x[0, 2] - anchor[2])]]
        rows, cols, vals = [np.arange(3)], [np.arange(3)], [np.full(3, prior_w)]
        n_res = 3
        if len(odo):
            e = odo
            i, j = e[:, 0].astype(int), e[:, 1].astype(int)
            z, wxy, wth = e[:, 2:5], 1.0 / e[:, 5], 1.0 / e[:, 6]
            d = x[j, :2] - x[i, :2]
            c, s = np.cos(x[i, 2]), np.sin(x[i, 2])
            local = np.stack([c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1]], 1)
            r = np.column_stack(
                [(local - z[:, :2]) * wxy[:, None], wrap_angle(x[j, 2] - x[i, 2] - z[:, 2]) * wth]
            )
            res.append(r.ravel())
            k = n_res + 3 * np.arange(len(e))
            dlx_dth = -s * d[:, 0] + c * d[:, 1]
            dly_dth = -c * d[:, 0] - s * d[:, 1]
            entries = [  # (row offset, pose, variable, value)
                (0, i, 0, -c * wxy), (0, i, 1, -s * wxy), (0, i, 2, dlx_dth * wxy),
                (0, j, 0, c * wxy), (0, j, 1, s * wxy),
                (1, i, 0, s * wxy), (1, i, 1, -c * wxy), (1, i, 2, dly_dth * wxy),
                (1, j, 0, -s * wxy), (1, j, 1, c * wxy),
                (2, i, 2, -wth), (2, j, 2, wth),
            ]  # fmt: skip
            for off, pose, var, val in entries:
                rows.append(k + off)
                cols.append(3 * pose + var)
                vals.append(np.broadcast_to(val, k.shape))
            n_res += 3 * len(e)
        errors = np.zeros(0)
        if len(rng):
            e = rng
            i, j = e[:, 0].astype(int), e[:, 1].astype(int)
            d = x[j, :2] - x[i, :2]
            length = np.maximum(np.linalg.norm(d, axis=1), 1e-9)
            u = d / length[:, None]
            errors = (length - e[:, 2]) / e[:, 3]
            w = (1.0 / e[:, 3]) * (
                np.sqrt(robust_weights[: len(e)]) if robust_weights is not None else 1.0
            )
            res.append(errors * (w * e[:, 3]))
            k = n_res + np.arange(len(e))
            for pose, sign in ((i, -1.0), (j, 1.0)):
                for var in (0, 1):
                    rows.append(k)
                    cols.append(3 * pose + var)
                    vals.append(sign * u[:, var] * w)
            n_res += len(e)
        if len(rot):
            e = rot
            i, j = e[:, 0].astype(int), e[:, 1].astype(int)
            rot_errors = wrap_angle(x[j, 2] - x[i, 2] - e[:, 2]) / e[:, 3]
            mine = slice(len(rng), len(rng) + len(rot))
            w = (1.0 / e[:, 3]) * (
                np.sqrt(robust_weights[mine]) if robust_weights is not None else 1.0
            )
            res.append(rot_errors * (w * e[:, 3]))
            k = n_res + np.arange(len(e))
            rows += [k, k]
            cols += [3 * i + 2, 3 * j + 2]
            vals += [-w * np.ones(len(e)), w * np.ones(len(e))]
            n_res += len(e)
            errors = np.concatenate([errors, rot_errors])
        if len(lat):
            e = lat
            i, j = e[:, 0].astype(int), e[:, 1].astype(int)
            d = x[j, :2] - x[i, :2]
            c, s = np.cos(x[i, 2]), np.sin(x[i, 2])
            lat_errors = (-s * d[:, 0] + c * d[:, 1] - e[:, 2]) / e[:, 3]
            start = len(rng) + len(rot)
            w = (1.0 / e[:, 3]) * (
                np.sqrt(robust_weights[start:]) if robust_weights is not None else 1.0
            )
            res.append(lat_errors * (w * e[:, 3]))
            k = n_res + np.arange(len(e))
            for pose, var, val in (
                (i, 0, s * w), (i, 1, -c * w), (i, 2, (-c * d[:, 0] - s * d[:, 1]) * w),
                (j, 0, -s * w), (j, 1, c * w),
            ):  # fmt: skip
                rows.append(k)
                cols.append(3 * pose + var)
                vals.append(val)
            n_res += len(e)
            errors = np.concatenate([errors, lat_errors])
        jac = sp.csr_matrix(
            (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
            shape=(n_res, 3 * self.n_poses),
        )
        return np.concatenate(res), jac, errors

    def _robust_weights(self, errors: np.ndarray) -> np.ndarray:
        """Each range, rotation then lateral edge's IRLS weight from its whitened error."""
        k = np.r_[
            np.full(len(self._rng), float(self.robust_scale)),
            [e[4] for e in self._rot],
            [e[4] for e in self._lat],
        ]
        a = np.abs(errors)
        if self.robust == "huber":
            return np.where(a <= k, 1.0, k / np.maximum(a, 1e-12))
        if self.robust == "cauchy":
            return 1.0 / (1.0 + (a / k) ** 2)
        return np.ones_like(errors)

    def optimize(
        self,
        poses: np.ndarray,
        iterations: int = 50,
        tolerance: float = 1e-9,
        relative_decrease: float = 1e-6,
    ) -> np.ndarray:
        """Poses ``(n_poses, 3)`` that minimise Eq. 1 from ``poses`` (the first one stays); stops
        after ``iterations``, or when a step moves no coordinate by ``tolerance`` or lowers the
        cost by less than ``relative_decrease`` of it."""
        x = np.array(poses, np.float64).reshape(self.n_poses, 3)
        anchor = x[0].copy()
        edges = (
            np.array(self._odo).reshape(-1, 7),
            np.array(self._rng).reshape(-1, 4),
            np.array(self._rot).reshape(-1, 5),
            np.array(self._lat).reshape(-1, 5),
        )
        lam, nu = 1e-3, 2.0  # damping, and its growth after a rejected step (Nielsen)
        _, _, errors = self._linearize(x, anchor, None, edges)
        weights = self._robust_weights(errors)
        for _ in range(iterations):
            r, jac, _ = self._linearize(x, anchor, weights, edges)
            cost = float(r @ r)
            jt = jac.T.tocsr()
            h = (jt @ jac).tocsc()
            g = jt @ r
            diag = np.maximum(h.diagonal(), 1e-9)
            while True:
                step = spsolve(h + sp.diags(lam * diag), -g, permc_spec="MMD_AT_PLUS_A")
                trial = x + step.reshape(-1, 3)
                trial[:, 2] = wrap_angle(trial[:, 2])
                r_new, _, _ = self._linearize(trial, anchor, weights, edges)
                new_cost = float(r_new @ r_new)
                predicted = -2.0 * float(step @ g) - float(step @ (h @ step))
                rho = (cost - new_cost) / predicted if predicted > 0 else -1.0
                if rho > 0:  # accepted: trust the model more the better it predicted
                    x = trial
                    lam *= max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3)
                    nu = 2.0
                    break
                lam, nu = lam * nu, 2.0 * nu
                if lam > 1e12:
                    return x
            _, _, errors = self._linearize(x, anchor, None, edges)
            weights = self._robust_weights(errors)  # reweight (IRLS)
            if np.abs(step).max() < tolerance or cost - new_cost < relative_decrease * cost:
                break
        return x
