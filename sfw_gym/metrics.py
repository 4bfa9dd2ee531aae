"""Every score in one place: maps (coverage, the paper's IoU, free-space IoU, wall precision and
recall, k accuracy; :mod:`sfw_gym.mapping.metrics`) and trajectories (ATE, RPE;
:mod:`sfw_gym.slam.metrics`)."""

from sfw_gym.mapping.metrics import (
    coverage,
    entropy_bits,
    evaluate_map,
    free_iou,
    interior_wall_recall,
    k_value_accuracy,
    map_iou,
    map_mse,
    wall_precision,
)
from sfw_gym.slam.metrics import absolute_trajectory_error, relative_pose_error

__all__ = [
    "absolute_trajectory_error",
    "coverage",
    "entropy_bits",
    "evaluate_map",
    "free_iou",
    "interior_wall_recall",
    "k_value_accuracy",
    "map_iou",
    "map_mse",
    "relative_pose_error",
    "wall_precision",
]
