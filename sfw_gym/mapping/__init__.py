"""What the robot believes: grid geometry, RSSI->k estimation, sparse/dense inverse k-visibility.

This package takes positions, RSSI vectors and router positions only; it imports nothing from
:mod:`sfw_gym.world`.
"""

from __future__ import annotations

from sfw_gym.mapping.config import MapperConfig
from sfw_gym.mapping.dense import dense_inverse_k_visibility
from sfw_gym.mapping.dry_run import DryRun
from sfw_gym.mapping.grid import GridSpec, belief_classes
from sfw_gym.mapping.k_estimation import KEstimator
from sfw_gym.mapping.lidar_map import LidarOccupancyMap
from sfw_gym.mapping.raycast import ray_cells, traverse_grid
from sfw_gym.mapping.sparse import GAIN_SOURCES, MapperState, SparseInverseKVisibility

__all__ = [
    "GAIN_SOURCES",
    "DryRun",
    "GridSpec",
    "KEstimator",
    "LidarOccupancyMap",
    "MapperConfig",
    "MapperState",
    "SparseInverseKVisibility",
    "belief_classes",
    "dense_inverse_k_visibility",
    "ray_cells",
    "traverse_grid",
]
