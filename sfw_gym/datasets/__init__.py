"""Real WiFi fingerprint data: one :class:`Fingerprints` type (positions in metres, RSSI with "not
heard" kept apart, access point names, optional floor, building, trajectory and time) and its
readers: the generic CSV (the command line's contract), UJIIndoorLoc and WiFine."""

from __future__ import annotations

from sfw_gym.datasets.fingerprints import META_COLUMNS, Fingerprints
from sfw_gym.datasets.odometry import (
    DRIFT_HEADING_STD_RAD,
    DRIFT_TRANSLATION_STD,
    synthetic_odometry,
    walk_poses,
)
from sfw_gym.datasets.readers import (
    GENERIC_NOT_HEARD,
    WIFINE_FLOORS,
    concatenate,
    read_csv,
    read_ujiindoorloc,
    read_wifine,
    write_wifine_maps,
)

__all__ = [
    "DRIFT_HEADING_STD_RAD",
    "DRIFT_TRANSLATION_STD",
    "GENERIC_NOT_HEARD",
    "META_COLUMNS",
    "WIFINE_FLOORS",
    "Fingerprints",
    "concatenate",
    "read_csv",
    "read_ujiindoorloc",
    "read_wifine",
    "synthetic_odometry",
    "walk_poses",
    "write_wifine_maps",
]
