"""Radio SLAM as the robot drives: poses and fingerprints arrive one at a time, and every
``config.solve_every`` poses the whole pose graph is solved again, warm-started from the last
solution."""

from __future__ import annotations

import numpy as np

from sfw_gym.core.buffers import AppendOnlyArray
from sfw_gym.core.errors import ConfigError
from sfw_gym.slam.pose_graph import chain
from sfw_gym.slam.radio_lidar import LidarSlamConfig, lidar_slam
from sfw_gym.slam.radio_slam import RadioSlamConfig, fit_range_model, radio_slam
from sfw_gym.slam.range_model import SimilarityRangeModel
from sfw_gym.slam.scan_matching import IcpConfig, IcpResult


class OnlineRadioSlam:
    """Odometry poses and fingerprints in, the current best trajectory out.

    Args:
        config: Radio SLAM's settings (``solve_every``: poses between solves).
        moved_m: A pose counts as corrected when a solution moves it further than this.
    """

    def __init__(self, config: RadioSlamConfig | None = None, moved_m: float = 0.05) -> None:
        self.config = config or RadioSlamConfig()
        self.moved_m = float(moved_m)
        self._odometry = AppendOnlyArray(3)
        self._fingerprints: AppendOnlyArray | None = None
        self._solved = np.zeros((0, 3))  # the last solution, for the poses it covered
        self.model = SimilarityRangeModel()  # Eq. 3, fit online on the pairs of each new pose
        self.n_solves = 0

    def __len__(self) -> int:
        return len(self._odometry)

    @property
    def odometry(self) -> np.ndarray:
        """``(N, 3)`` the odometry poses so far (read-only)."""
        return self._odometry.view

    def add(self, odometry_pose, fingerprint, scan: np.ndarray | None = None) -> int | None:
        """Take one pose's odometry ``(x, y, θ)`` and fingerprint ``(L,)`` (dBm, NaN: not
        heard) and, where there is a LiDAR, its scan points ``(M, 2)`` in the robot's frame
        (unused by Radio SLAM); returns the first pose that a new solution moved by more than
        ``moved_m``, or None when nothing was solved or moved."""
        fingerprint = np.asarray(fingerprint, np.float64)
        if self._fingerprints is None:
            self._fingerprints = AppendOnlyArray(len(fingerprint))
        self._odometry.append(odometry_pose)
        self._fingerprints.append(fingerprint)
        n, every = len(self), self.config.solve_every
        if n % every or n < 2:
            return None
        odometry, fingerprints = self._odometry.view, self._fingerprints.view
        fit_range_model(self.model, odometry, fingerprints, self.config, since=n - every)
        before = self.estimate()
        after = self._solve(odometry, fingerprints, before)
        self._solved = after
        self.n_solves += 1
        moved = np.flatnonzero(np.hypot(*(after[:, :2] - before[:, :2]).T) > self.moved_m)
        return int(moved[0]) if len(moved) else None

    def _solve(self, odometry: np.ndarray, fingerprints: np.ndarray, before: np.ndarray):
        return radio_slam(odometry, fingerprints, self.config, before, self.model).poses

    def estimate(self) -> np.ndarray:
        """``(N, 3)`` poses: the last solution, then odometry chained on from its last pose."""
        odometry = self._odometry.view
        m = len(self._solved)
        if m == 0:
            return odometry.copy()
        tail = chain(self._solved[-1], odometry[m - 1], odometry[m:])
        return np.concatenate([self._solved, tail])

    def latest(self) -> np.ndarray:
        """The current pose ``(3,)``."""
        odometry = self._odometry.view
        m = len(self._solved)
        if m == 0:
            return odometry[-1].copy()
        return chain(self._solved[-1], odometry[m - 1], odometry[-1:])[0]


class OnlineRadioLidarSlam(OnlineRadioSlam):
    """Radio+LiDAR SLAM as the robot drives: as :class:`OnlineRadioSlam`, with each pose's LiDAR
    scan (points in the robot's frame; kept at keyframes) and :func:`lidar_slam` as the solver
    (consecutive registrations cached between solves)."""

    def __init__(
        self,
        config: RadioSlamConfig | None = None,
        lidar_config: LidarSlamConfig | None = None,
        icp_config: IcpConfig | None = None,
        moved_m: float = 0.05,
    ) -> None:
        super().__init__(config, moved_m)
        self.lidar_config = lidar_config or LidarSlamConfig()
        self.icp_config = icp_config or IcpConfig()
        self._scans: dict[int, np.ndarray] = {}
        self._registrations: dict[tuple[int, int], IcpResult] = {}

    def add(self, odometry_pose, fingerprint, scan: np.ndarray | None = None) -> int | None:
        if scan is None:
            raise ConfigError("Radio+LiDAR SLAM needs each pose's LiDAR scan")
        index = len(self)
        self._scans[index] = np.asarray(scan, np.float64)
        if index > 0 and (index - 1) % self.config.keyframe_every:
            del self._scans[index - 1]  # kept only while it was the latest pose
        return super().add(odometry_pose, fingerprint)

    def _solve(self, odometry: np.ndarray, fingerprints: np.ndarray, before: np.ndarray):
        return lidar_slam(
            odometry,
            self._scans,
            fingerprints,
            radio=self.config,
            config=self.lidar_config,
            icp_config=self.icp_config,
            initial=before,
            model=self.model,
            cache=self._registrations,
        ).poses
