"""The paper's Eq. 3: the distance between two places given their fingerprints' similarity,
learned by binning pairs whose distance odometry knows (short stretches, where it has not
drifted yet)."""

from __future__ import annotations

import numpy as np

from sfw_gym.core.errors import ConfigError


class SimilarityRangeModel:
    """Mean and variance of the distance per similarity bin of width ``bin_width`` over [0, 1].

    The paper prints the mean as the bin's mean of d²; its variance is centred on the mean
    distance, so the mean here is the mean of d (the printed square is taken for a typo).
    Samples accumulate (:meth:`update`, online); a bin with fewer than ``min_samples`` has no
    estimate (NaN).
    """

    def __init__(self, bin_width: float = 0.05, min_samples: int = 5) -> None:
        if not 0.0 < bin_width <= 1.0:
            raise ConfigError(f"bin_width must be in (0, 1], got {bin_width!r}")
        self.n_bins = int(np.ceil(1.0 / bin_width - 1e-9))
        self.min_samples = int(min_samples)
        self._n = np.zeros(self.n_bins)
        self._sum = np.zeros(self.n_bins)
        self._sum_sq = np.zeros(self.n_bins)

    def _bin(self, similarity: np.ndarray) -> np.ndarray:
        s = np.clip(np.asarray(similarity, np.float64), 0.0, 1.0)
        return np.minimum((s * self.n_bins).astype(np.int64), self.n_bins - 1)

    def update(self, similarity: np.ndarray, distance_m: np.ndarray) -> None:
        """Add pairs (similarity, distance in metres)."""
        s, d = np.broadcast_arrays(np.asarray(similarity, np.float64), np.asarray(distance_m))
        ok = np.isfinite(s) & np.isfinite(d)
        b = self._bin(s[ok])
        np.add.at(self._n, b, 1.0)
        np.add.at(self._sum, b, d[ok])
        np.add.at(self._sum_sq, b, d[ok] ** 2)

    def predict(self, similarity: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(mean distance, variance)`` for each similarity (NaN where the bin has too few)."""
        b = self._bin(similarity)
        n = self._n[b]
        enough = n >= self.min_samples
        with np.errstate(divide="ignore", invalid="ignore"):
            mean = np.where(enough, self._sum[b] / n, np.nan)
            var = np.where(enough, np.maximum(self._sum_sq[b] / n - mean**2, 0.0), np.nan)
        return mean, var
