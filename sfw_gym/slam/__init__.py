"""Radio SLAM from WiFi fingerprints (Liu et al., "Exploiting Radio Fingerprints for SLAM"):
fingerprint similarity (Eq. 2), the similarity → distance model (Eq. 3), and an SE(2) pose graph
of odometry and range edges optimised by a sparse Levenberg–Marquardt with a robust kernel
(Eq. 1); :func:`radio_slam`, which puts them together on a run's odometry and fingerprints,
:class:`OnlineRadioSlam`, which does so as the robot drives (the env's ``pose_source=
"radio_slam"``), and the trajectory errors ATE and RPE. The paper's second system,
Radio+LiDAR SLAM (:func:`lidar_slam`, ICP scan matching in :mod:`.scan_matching`), and its
LiDAR-only baseline."""

from __future__ import annotations

from sfw_gym.slam.fingerprints import closure_candidates, cosine_similarity, kernel_similarity
from sfw_gym.slam.metrics import absolute_trajectory_error, relative_pose_error
from sfw_gym.slam.online import OnlineRadioLidarSlam, OnlineRadioSlam
from sfw_gym.slam.pose_graph import PoseGraph, compose_pose, relative_pose
from sfw_gym.slam.radio_lidar import LidarSlamConfig, LidarSlamResult, lidar_slam
from sfw_gym.slam.radio_slam import RadioSlamConfig, RadioSlamResult, radio_slam
from sfw_gym.slam.range_model import SimilarityRangeModel
from sfw_gym.slam.scan_matching import IcpConfig, IcpResult, icp

__all__ = [
    "IcpConfig",
    "IcpResult",
    "LidarSlamConfig",
    "LidarSlamResult",
    "OnlineRadioLidarSlam",
    "OnlineRadioSlam",
    "PoseGraph",
    "RadioSlamConfig",
    "RadioSlamResult",
    "SimilarityRangeModel",
    "absolute_trajectory_error",
    "closure_candidates",
    "compose_pose",
    "cosine_similarity",
    "icp",
    "kernel_similarity",
    "lidar_slam",
    "radio_slam",
    "relative_pose",
    "relative_pose_error",
]
