"""Every score in one place: maps (coverage, the paper's IoU, free-space IoU, wall precision and
recall, k accuracy; :mod:`sfw_gym.mapping.metrics`), trajectories (ATE, RPE;
:mod:`sfw_gym.slam.metrics`) and the cells left unknown between the true router zones
(:func:`zone_band_unknown`)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from sfw_gym.core.constants import U8_FREE
from sfw_gym.mapping.grid import belief_classes
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

if TYPE_CHECKING:
    from sfw_gym.mapping.grid import GridSpec
    from sfw_gym.world.radio import RadioModel

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
    "zone_band_unknown",
]


def zone_band_unknown(
    truth_u8: np.ndarray,
    belief_u8: np.ndarray,
    grid: GridSpec,
    radio: RadioModel,
    band_m: float = 0.8,
) -> dict[str, float]:
    """Free cells left unknown along the borders between the true router dominance zones.

    Zones: each free cell of the ground truth goes to the router with the highest noise-free
    RSSI there (path loss, walls, shadowing). Band: free cells within ``band_m`` of a cell of
    another zone. Unknown: neither free nor wall on the belief map. Ground truth: for
    evaluation only.

    Args:
        truth_u8: The true grid on the belief's cells (255 free).
        belief_u8: The belief map (uint8, 0 wall, 255 free, 127 unknown).
        grid: The maps' geometry (cell centres, resolution).
        radio: The radio model (``routers``, noise-free ``mean_rssi``).
        band_m: Half-width of the bands.

    Returns:
        ``zone_band_cells``, ``zone_band_unknown`` (cells), ``zone_band_unknown_frac``.
    """
    from scipy import ndimage

    free = truth_u8 == U8_FREE
    if len(radio.routers) < 2 or not free.any():
        return {"zone_band_cells": 0, "zone_band_unknown": 0, "zone_band_unknown_frac": 0.0}
    xs, ys = grid.cell_centres()
    zone = np.full(truth_u8.shape, -1, np.int64)
    zone[free] = np.argmax(radio.mean_rssi(np.stack([xs[free], ys[free]], 1)), axis=1)
    border = np.zeros(truth_u8.shape, bool)
    for a, b in (
        ((slice(None, -1), slice(None)), (slice(1, None), slice(None))),
        ((slice(None), slice(None, -1)), (slice(None), slice(1, None))),
    ):
        diff = (zone[a] != zone[b]) & (zone[a] >= 0) & (zone[b] >= 0)
        border[a] |= diff
        border[b] |= diff
    if not border.any():
        return {"zone_band_cells": 0, "zone_band_unknown": 0, "zone_band_unknown_frac": 0.0}
    band = free & (ndimage.distance_transform_edt(~border) * grid.resolution_m <= band_m)
    est_free, wall, _ = belief_classes(belief_u8)
    unknown = band & ~wall & ~est_free
    n_band = int(band.sum())
    return {
        "zone_band_cells": n_band,
        "zone_band_unknown": int(unknown.sum()),
        "zone_band_unknown_frac": float(unknown.sum() / n_band) if n_band else 0.0,
    }
