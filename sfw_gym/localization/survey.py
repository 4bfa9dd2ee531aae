"""A WiFi survey: fingerprints along a trajectory, normalised as the paper does, and binned so
that a GP fit stays affordable."""

from __future__ import annotations

import csv
import math
import os
from dataclasses import dataclass

import numpy as np

from sfw_gym.core.constants import NOT_HEARD_DBM
from sfw_gym.core.errors import ConfigError


def normalise_rssi(dbm: np.ndarray) -> np.ndarray:
    """dBm → [0, 1] (the paper's scale: 0 dBm → 1, −100 dBm → 0); not heard (NaN or ≤ −100) → 0."""
    z = (np.asarray(dbm, np.float64) - NOT_HEARD_DBM) / -NOT_HEARD_DBM
    return np.clip(np.nan_to_num(z, nan=0.0), 0.0, 1.0)


@dataclass(frozen=True)
class Survey:
    """Positions ``(N, 2)`` in metres and their fingerprints ``(N, L)`` normalised to [0, 1]
    (0: not heard)."""

    positions: np.ndarray
    signals: np.ndarray

    def __post_init__(self) -> None:
        p, z = np.asarray(self.positions, np.float64), np.asarray(self.signals, np.float64)
        if p.ndim != 2 or p.shape[1] != 2 or z.ndim != 2 or len(p) != len(z) or len(p) == 0:
            raise ConfigError(
                f"a survey needs positions (N, 2) and signals (N, L), got {p.shape}, {z.shape}"
            )
        if not (np.isfinite(p).all() and np.isfinite(z).all()):
            raise ConfigError("survey positions and signals must be finite")
        object.__setattr__(self, "positions", p)
        object.__setattr__(self, "signals", z)

    @classmethod
    def from_dbm(cls, positions: np.ndarray, rssi_dbm: np.ndarray) -> Survey:
        """From readings in dBm (NaN or ≤ −100: not heard)."""
        return cls(np.asarray(positions, np.float64), normalise_rssi(rssi_dbm))

    @classmethod
    def from_csv(cls, path: str | os.PathLike[str]) -> Survey:
        """A CSV with a header ``x, y`` (metres), then one column per access point (dBm; empty,
        ``nan`` or ≤ −100: not heard); ConfigError naming the file and line otherwise."""
        try:
            with open(path, encoding="utf-8-sig", newline="") as fh:
                rows = [
                    (n, r) for n, r in enumerate(csv.reader(fh), 1) if any(c.strip() for c in r)
                ]
        except (OSError, UnicodeDecodeError, csv.Error) as exc:
            raise ConfigError(f"{path}: cannot read the survey: {exc}") from None
        header = [c.strip() for c in rows[0][1]] if rows else []
        if header[:2] != ["x", "y"] or len(header) < 3:
            raise ConfigError(
                f"{path}: a survey's header is x, y, then one column per access point; "
                f"found {header[:6]}"
            )
        values = np.empty((len(rows) - 1, len(header)))
        for k, (line, row) in enumerate(rows[1:]):
            if len(row) != len(header):
                raise ConfigError(f"{path}:{line}: {len(row)} values, the header has {len(header)}")
            for c, text in enumerate(row):
                try:
                    values[k, c] = float(text) if text.strip() else math.nan
                except ValueError:
                    raise ConfigError(
                        f"{path}:{line}: {header[c]} is not a number: {text!r}"
                    ) from None
        if not len(values) or not np.isfinite(values[:, :2]).all():
            raise ConfigError(f"{path}: no rows, or a position that is not a finite number")
        return cls.from_dbm(values[:, :2], values[:, 2:])

    @property
    def n_access_points(self) -> int:
        return int(self.signals.shape[1])

    def binned(self, cell_m: float = 0.25) -> Survey:
        """One sample per ``cell_m`` square cell the survey passed through: the mean position and
        the mean signal of its readings (a GP fit is cubic in the samples: 2.3 s per AP at 500,
        236 s at 4,000)."""
        if not cell_m > 0:
            raise ConfigError(f"cell_m must be > 0, got {cell_m!r}")
        cells = np.floor(self.positions / cell_m).astype(np.int64)
        _, index, counts = np.unique(cells, axis=0, return_inverse=True, return_counts=True)
        index = index.ravel()
        positions = np.zeros((len(counts), 2))
        signals = np.zeros((len(counts), self.n_access_points))
        np.add.at(positions, index, self.positions)
        np.add.at(signals, index, self.signals)
        return Survey(positions / counts[:, None], signals / counts[:, None])
