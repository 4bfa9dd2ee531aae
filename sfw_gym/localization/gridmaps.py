"""Gaussian gridmaps (the paper's Sec. II-A): a GP's predicted mean and variance stored per cell,
so that a prediction is a lookup (Eq. 11) instead of an O(n²) GP evaluation."""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from sfw_gym.core.atomic import atomic_path
from sfw_gym.core.errors import ConfigError
from sfw_gym.localization.gp import SignalModel

DTYPES = ("float64", "float16", "uint8")
_U8_MAX = 255.0


@dataclass(frozen=True)
class GaussianGridmaps:
    """Mean and variance gridmaps ``(L, h, w)`` of L access points over cells of ``resolution_m``
    whose bottom-left corner is ``origin_xy``; each stored as float64, float16 or uint8 (uint8: the
    mean × 255 and the variance × 255 / its maximum, at least 1, as the paper does)."""

    mean: np.ndarray
    variance: np.ndarray
    origin_xy: tuple[float, float]
    resolution_m: float
    variance_scale: np.ndarray  # (L,) the maximum variance of each map (uint8: 255 ↔ it)

    @classmethod
    def from_model(
        cls,
        model: SignalModel,
        bounds: tuple[float, float, float, float],
        resolution_m: float,
        dtype: str | tuple[str, str] = "float64",
    ) -> GaussianGridmaps:
        """Predict ``model`` at every cell centre of ``bounds`` ``(x0, y0, x1, y1)``; ``dtype``:
        one for both maps, or ``(mean's, variance's)``."""
        if not resolution_m > 0:
            raise ConfigError(f"resolution_m must be > 0, got {resolution_m!r}")
        x0, y0, x1, y1 = map(float, bounds)
        w = max(1, int(np.ceil((x1 - x0) / resolution_m)))
        h = max(1, int(np.ceil((y1 - y0) / resolution_m)))
        # row 0 is the top (the paper's Eq. 11 counts rows down from y1)
        xs = x0 + (np.arange(w) + 0.5) * resolution_m
        ys = y0 + (h - np.arange(h) - 0.5) * resolution_m
        gx, gy = np.meshgrid(xs, ys)
        mean, var = model.predict(np.column_stack([gx.ravel(), gy.ravel()]))
        mean = mean.T.reshape(-1, h, w)
        var = var.T.reshape(-1, h, w)
        scale = np.asarray(model.max_variance, np.float64)
        if len(scale) == 1:
            scale = np.repeat(scale, model.n_access_points)
        return cls.quantised(mean, var, (x0, y0), resolution_m, scale, dtype)

    @classmethod
    def quantised(cls, mean, var, origin_xy, resolution_m, scale, dtype) -> GaussianGridmaps:
        """Store float maps ``(L, h, w)`` as ``dtype`` (one, or ``(mean's, variance's)``)."""
        mean_dtype, var_dtype = (dtype, dtype) if isinstance(dtype, str) else dtype
        for d in (mean_dtype, var_dtype):
            if d not in DTYPES:
                raise ConfigError(f"dtype must be one of {DTYPES}, got {d!r}")
        scale = np.asarray(scale, np.float64)
        if mean_dtype == "uint8":
            m = np.clip(np.rint(mean * _U8_MAX), 0, 255).astype(np.uint8)
        else:
            m = mean.astype(mean_dtype)
        if var_dtype == "uint8":
            v = np.clip(np.rint(var / scale[:, None, None] * _U8_MAX), 1, 255).astype(np.uint8)
        else:
            v = var.astype(var_dtype)
        origin = (float(origin_xy[0]), float(origin_xy[1]))
        return cls(m, v, origin, float(resolution_m), np.asarray(scale, np.float64))

    @property
    def shape(self) -> tuple[int, int]:
        """``(h, w)`` cells."""
        return self.mean.shape[1], self.mean.shape[2]

    @property
    def memory_bytes(self) -> int:
        """Bytes of the mean and variance maps."""
        return int(self.mean.nbytes + self.variance.nbytes)

    def cells(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Eq. 11: the (row, column) of each location ``(N, 2)``, clamped to the map (rows
        counted from the top, 0-based)."""
        h, w = self.shape
        xy = np.asarray(xy, np.float64).reshape(-1, 2)
        col = np.floor((xy[:, 0] - self.origin_xy[0]) / self.resolution_m).astype(np.int64)
        row = h - 1 - np.floor((xy[:, 1] - self.origin_xy[1]) / self.resolution_m).astype(np.int64)
        return np.clip(row, 0, h - 1), np.clip(col, 0, w - 1)

    def lookup(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Mean and variance ``(N, L)`` (float64) at locations ``(N, 2)``."""
        row, col = self.cells(xy)
        mean = self.mean[:, row, col].T.astype(np.float64)
        var = self.variance[:, row, col].T.astype(np.float64)
        if self.mean.dtype == np.uint8:
            mean /= _U8_MAX
        if self.variance.dtype == np.uint8:
            var *= self.variance_scale / _U8_MAX
        return mean, var

    def cell_centres(self) -> np.ndarray:
        """``(h * w, 2)`` the centre of every cell, row by row from the top."""
        h, w = self.shape
        xs = self.origin_xy[0] + (np.arange(w) + 0.5) * self.resolution_m
        ys = self.origin_xy[1] + (h - np.arange(h) - 0.5) * self.resolution_m
        gx, gy = np.meshgrid(xs, ys)
        return np.column_stack([gx.ravel(), gy.ravel()])

    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write ``.npz`` (atomically)."""
        with atomic_path(path) as tmp:
            np.savez_compressed(
                tmp,
                mean=self.mean,
                variance=self.variance,
                origin_xy=np.array(self.origin_xy),
                resolution_m=np.array(self.resolution_m),
                variance_scale=self.variance_scale,
            )
        return Path(path)

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> GaussianGridmaps:
        """Read what :meth:`save` wrote; ConfigError naming the file otherwise."""
        try:
            with np.load(path) as data:
                return cls(
                    data["mean"],
                    data["variance"],
                    (float(data["origin_xy"][0]), float(data["origin_xy"][1])),
                    float(data["resolution_m"]),
                    data["variance_scale"],
                )
        except (OSError, KeyError, ValueError) as exc:
            raise ConfigError(f"{path}: not Gaussian gridmaps ({exc})") from None
