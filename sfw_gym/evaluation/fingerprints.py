"""``sfw-gym fingerprints evaluate``: a localiser fit on one fingerprint file and scored on
another (errors in the data's own units), per scan or tracking each walk with WiFi MCL on the
Gaussian gridmaps over synthetic odometry; ``metrics.json`` and ``predictions.csv``."""

from __future__ import annotations

import json
import os
import time
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from sfw_gym.core.atomic import atomic_path, write_text_atomic
from sfw_gym.core.errors import ConfigError
from sfw_gym.datasets import (
    DRIFT_HEADING_STD_RAD,
    DRIFT_TRANSLATION_STD,
    Fingerprints,
    synthetic_odometry,
)
from sfw_gym.localization.fingerprinting import (
    DEFAULT_METHOD,
    GridmapLocalizer,
    Prediction,
    make_localizer,
)
from sfw_gym.localization.tracking import TRACK_PARTICLES, WALL_WEIGHT, track_walk
from sfw_gym.world.floorplan import Floorplan


@dataclass(frozen=True)
class TrackSettings:
    """``--track``: the synthetic odometry's noise, its seed, the particles, floorplans (by
    floor; the key None, or one plan alone: every floor) and the weight a particle keeps when
    it crosses a wall."""

    translation_std: float = DRIFT_TRANSLATION_STD
    heading_std_rad: float = DRIFT_HEADING_STD_RAD
    seed: int = 0
    particles: int = TRACK_PARTICLES
    floorplans: Mapping[int | None, Floorplan] | Floorplan | None = None
    wall_weight: float = WALL_WEIGHT

    def plan_for(self, floor: int | None) -> Floorplan | None:
        """The plan of ``floor`` (one :class:`Floorplan` given: the plan of every floor)."""
        if isinstance(self.floorplans, Floorplan):
            return self.floorplans
        plans = self.floorplans or {}
        return plans.get(floor, plans.get(None))


def error_metrics(errors: np.ndarray, prefix: str = "") -> dict[str, float]:
    """Mean, median, 75th and 95th percentile of per-scan errors."""
    return {
        f"{prefix}mean_error_m": float(np.mean(errors)),
        f"{prefix}median_error_m": float(np.median(errors)),
        f"{prefix}p75_error_m": float(np.percentile(errors, 75)),
        f"{prefix}p95_error_m": float(np.percentile(errors, 95)),
    }


def evaluate(
    train: Fingerprints,
    test: Fingerprints,
    method: str = DEFAULT_METHOD,
    track: TrackSettings | None = None,
) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
    """Fit ``method`` on ``train``, locate every scan of ``test``; with ``track``, each walk of
    ``test`` (:meth:`Fingerprints.walks`) is tracked instead. Returns (metrics, prediction
    columns)."""
    test = test.aligned_to(train.access_points)
    start = time.perf_counter()
    localizer = make_localizer(method).fit(train)
    fit_s = time.perf_counter() - start
    per_scan = localizer.predict(test)
    metrics: dict[str, Any] = {"method": method, "n_test": len(test), "fit_s": fit_s}
    metrics["query_ms_per_scan"] = per_scan.query_s_per_scan * 1e3
    columns = _columns(test, per_scan)
    errors = columns["error_m"]
    if track is not None:
        metrics["per_scan_mean_error_m"] = float(np.mean(errors))
        tracked, track_info = _track(train, test, localizer, per_scan, track)
        columns["per_scan_x"], columns["per_scan_y"] = columns.pop("x"), columns.pop("y")
        columns["x"], columns["y"] = tracked[:, 0], tracked[:, 1]
        columns["per_scan_error_m"] = errors
        errors = columns["error_m"] = np.hypot(*(tracked - test.positions).T)
        metrics.update(track_info)
    metrics.update(error_metrics(errors))
    if per_scan.floor is not None and test.floor is not None:
        metrics["floor_hit_rate"] = float(np.mean(per_scan.floor == test.floor))
    if per_scan.building is not None and test.building is not None:
        metrics["building_hit_rate"] = float(np.mean(per_scan.building == test.building))
    return metrics, columns


def _columns(test: Fingerprints, p: Prediction) -> dict[str, np.ndarray]:
    columns: dict[str, np.ndarray] = {
        "x_true": test.positions[:, 0],
        "y_true": test.positions[:, 1],
        "x": p.positions[:, 0],
        "y": p.positions[:, 1],
        "error_m": np.hypot(*(p.positions - test.positions).T),
    }
    for key, predicted in (("floor", p.floor), ("building", p.building)):
        if getattr(test, key) is not None:
            columns[f"{key}_true"] = getattr(test, key)
        if predicted is not None:
            columns[key] = predicted
    if test.trajectory is not None:
        columns["trajectory"] = test.trajectory
    if test.t is not None:
        columns["t"] = test.t
    return columns


def majority_key(building: np.ndarray, floor: np.ndarray) -> int:
    """The (building, floor) key (building × 1000 + floor) that most of a walk's scans were
    placed on: the walk is tracked there."""
    return int(np.bincount(np.asarray(building) * 1000 + np.asarray(floor)).argmax())


def _track(
    train: Fingerprints,
    test: Fingerprints,
    localizer,
    per_scan: Prediction,
    settings: TrackSettings,
) -> tuple[np.ndarray, dict[str, Any]]:
    """Each walk on the floor most of its scans were placed on, over synthetic odometry."""
    maps = localizer if isinstance(localizer, GridmapLocalizer) else GridmapLocalizer().fit(train)
    chosen = per_scan.floor if per_scan.floor is not None else np.zeros(len(test), np.int64)
    building = per_scan.building if per_scan.building is not None else np.zeros(len(test), int)
    tracked = np.empty((len(test), 2))
    start = time.perf_counter()
    walks = 0
    for walks, (_, rows) in enumerate(test.walks(), start=1):
        key = majority_key(building[rows], chosen[rows])
        increments, _ = synthetic_odometry(
            test.positions[rows],
            translation_std=settings.translation_std,
            heading_std_rad=settings.heading_std_rad,
            rng=[settings.seed, walks],
        )
        plan = settings.plan_for(key % 1000 if per_scan.floor is not None else None)
        walk = test.subset(rows)
        tracked[rows] = track_walk(
            maps.floors[key],
            walk.rssi_dbm,
            increments,
            plan=plan,
            particles=settings.particles,
            wall_weight=settings.wall_weight,
            sensor=_sensor(localizer, walk, key),
            rng=[settings.seed, walks, 1],
        )
    info = {
        "tracked_walks": walks,
        "sensor_model": "gridmaps" if isinstance(localizer, GridmapLocalizer) else "kernel",
        "wall_weight": settings.wall_weight,
        "odometry": "synthetic: true positions plus noise",
        "odometry_translation_std": settings.translation_std,
        "odometry_heading_std_rad": settings.heading_std_rad,
        "seed": settings.seed,
        "particles": settings.particles,
        "with_floorplan": bool(settings.floorplans),
        "track_s": time.perf_counter() - start,
    }
    return tracked, info


def _sensor(localizer, walk: Fingerprints, key: int):
    """The tracker's sensor model: a k-NN method's kernel density (its neighbours' positions,
    :meth:`KnnLocalizer.log_likelihood`), or None for the gridmaps' own."""
    if isinstance(localizer, GridmapLocalizer):
        return None

    def log_likelihood(k: int, xy: np.ndarray) -> np.ndarray:
        return localizer.log_likelihood(walk.subset([k]), key, xy)

    return log_likelihood


def write_evaluation(
    out: str | os.PathLike[str], metrics: Mapping[str, Any], columns: Mapping[str, np.ndarray]
) -> dict[str, Path]:
    """``out/metrics.json`` and ``out/predictions.csv`` (both atomically)."""
    import pandas as pd

    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ConfigError(f"--out {out}: exists and is not a folder")
    metrics_path = write_text_atomic(out / "metrics.json", json.dumps(metrics, indent=2) + "\n")
    predictions = out / "predictions.csv"
    with atomic_path(predictions) as tmp:
        pd.DataFrame(dict(columns)).to_csv(tmp, index=False, float_format="%.4f")
    return {"metrics": Path(metrics_path), "predictions": predictions}
