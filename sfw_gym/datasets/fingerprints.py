"""WiFi fingerprints: positions in metres and one RSSI reading per access point, "not heard"
kept apart from a reading (NaN), with optional floor, building, trajectory and time."""

from __future__ import annotations

import os
from collections.abc import Iterator
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from sfw_gym.core.atomic import atomic_path
from sfw_gym.core.errors import ConfigError

#: The generic CSV's columns that are not access points, in the order they are written.
META_COLUMNS = ("x", "y", "floor", "building", "trajectory", "t")


@dataclass(frozen=True, eq=False)
class Fingerprints:
    """``N`` fingerprints over ``L`` access points.

    Attributes:
        positions: ``(N, 2)`` x, y in metres (the dataset's frame).
        rssi_dbm: ``(N, L)`` readings in dBm; NaN where the access point was not heard.
        access_points: the ``L`` access points' names.
        floor, building: ``(N,)`` integers, or None where the data has none.
        trajectory: ``(N,)`` labels (str) of the walk each scan belongs to, or None.
        t: ``(N,)`` seconds, or None.
        name: where the data came from (a file name), for messages and reports.
    """

    positions: np.ndarray
    rssi_dbm: np.ndarray
    access_points: tuple[str, ...]
    floor: np.ndarray | None = None
    building: np.ndarray | None = None
    trajectory: np.ndarray | None = None
    t: np.ndarray | None = None
    name: str = "fingerprints"

    def __post_init__(self) -> None:
        p = np.asarray(self.positions, np.float64)
        r = np.asarray(self.rssi_dbm, np.float64)
        if p.ndim != 2 or p.shape[1] != 2 or r.ndim != 2 or len(p) != len(r):
            raise ConfigError(
                f"{self.name}: fingerprints need positions (N, 2) and readings (N, L), "
                f"got {p.shape} and {r.shape}"
            )
        if r.shape[1] != len(self.access_points):
            raise ConfigError(
                f"{self.name}: {r.shape[1]} reading columns for "
                f"{len(self.access_points)} access point names"
            )
        if len(set(self.access_points)) != len(self.access_points):
            raise ConfigError(f"{self.name}: access point names repeat")
        if not np.isfinite(p).all():
            raise ConfigError(f"{self.name}: a position is not a finite number")
        if np.isinf(r).any():
            raise ConfigError(f"{self.name}: a reading is infinite")
        object.__setattr__(self, "positions", p)
        object.__setattr__(self, "rssi_dbm", r)
        object.__setattr__(self, "access_points", tuple(map(str, self.access_points)))
        for key, kind in (("floor", np.int64), ("building", np.int64), ("t", np.float64)):
            value = getattr(self, key)
            if value is not None:
                object.__setattr__(self, key, self._column(value, key, kind))
        if self.trajectory is not None:
            labels = np.asarray(self.trajectory).astype(str)
            object.__setattr__(self, "trajectory", self._column(labels, "trajectory", None))

    def _column(self, value, key: str, kind) -> np.ndarray:
        array = np.asarray(value) if kind is None else np.asarray(value, kind)
        if array.shape != (len(self),):
            raise ConfigError(
                f"{self.name}: {key} has shape {array.shape}, expected ({len(self)},)"
            )
        return array

    def __len__(self) -> int:
        return len(self.positions)

    @property
    def n_access_points(self) -> int:
        return len(self.access_points)

    @property
    def heard(self) -> np.ndarray:
        """``(N, L)`` whether each access point was heard in each scan."""
        return ~np.isnan(self.rssi_dbm)

    def filled(self, not_heard_dbm: float) -> np.ndarray:
        """``(N, L)`` readings with "not heard" replaced by ``not_heard_dbm``."""
        return np.where(np.isnan(self.rssi_dbm), not_heard_dbm, self.rssi_dbm)

    def subset(self, rows: np.ndarray | list[int]) -> Fingerprints:
        """The scans picked by a boolean mask or an index array."""
        pick = np.asarray(rows)

        def take(a):
            return None if a is None else a[pick]

        return replace(
            self,
            positions=self.positions[pick],
            rssi_dbm=self.rssi_dbm[pick],
            floor=take(self.floor),
            building=take(self.building),
            trajectory=take(self.trajectory),
            t=take(self.t),
        )

    def aligned_to(self, access_points: tuple[str, ...]) -> Fingerprints:
        """These scans over ``access_points`` (a training set's): an access point this data lacks
        is not heard; one the training set lacks is dropped."""
        column = {ap: j for j, ap in enumerate(self.access_points)}
        rssi = np.full((len(self), len(access_points)), np.nan)
        for j, ap in enumerate(access_points):
            if ap in column:
                rssi[:, j] = self.rssi_dbm[:, column[ap]]
        return replace(self, rssi_dbm=rssi, access_points=tuple(access_points))

    def walks(self) -> Iterator[tuple[str, np.ndarray]]:
        """Each walk as (label, row indices in time order): the scans of one ``trajectory`` on
        one floor (a walk that changes floor is split there), ordered by ``t`` (by row where
        there is no time)."""
        if self.trajectory is None:
            raise ConfigError(f"{self.name}: no trajectory column, so no walks to track")
        order = np.arange(len(self)) if self.t is None else np.argsort(self.t, kind="stable")
        for label in dict.fromkeys(self.trajectory[order]):
            rows = order[self.trajectory[order] == label]
            if self.floor is None:
                yield str(label), rows
                continue
            breaks = np.flatnonzero(np.diff(self.floor[rows])) + 1
            pieces = np.split(rows, breaks)
            for k, piece in enumerate(pieces):
                yield (str(label) if len(pieces) == 1 else f"{label}#{k}"), piece

    def to_csv(self, path: str | os.PathLike[str]) -> Path:
        """Write the generic CSV (atomically): ``x, y``, the optional columns this data has, then
        one column per access point; not heard is an empty cell."""
        import pandas as pd

        columns: dict[str, np.ndarray] = {"x": self.positions[:, 0], "y": self.positions[:, 1]}
        for key in META_COLUMNS[2:]:
            if getattr(self, key) is not None:
                columns[key] = getattr(self, key)
        frame = pd.DataFrame(columns)
        readings = pd.DataFrame(self.rssi_dbm, columns=list(self.access_points))
        frame = pd.concat([frame, readings], axis=1)
        with atomic_path(path) as tmp:
            frame.to_csv(tmp, index=False, na_rep="", float_format="%.10g")
        return Path(path)
