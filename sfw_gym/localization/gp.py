"""Gaussian-process signal maps (the paper's Eqs. 1–9): location → normalised signal strength,
zero mean, an RBF kernel plus white noise, hyperparameters fit by maximum likelihood
(scikit-learn). ``GP``: one model for every AP (unheard readings count as 0); ``mGP``: one model
per AP trained only where that AP was heard. Our option ``mean="path_loss"``: a log-distance
path-loss curve per AP (its position, power and exponent fit by robust least squares) as the
GP's mean, the GP fit on what the curve leaves, so that far from the survey the prediction
follows the curve instead of falling to 0."""

from __future__ import annotations

import warnings

import numpy as np
from scipy.optimize import least_squares

from sfw_gym.core.errors import ConfigError
from sfw_gym.localization.survey import Survey

#: Where the fit starts, and the bounds it keeps to (metres for the lengthscale).
LENGTH_SCALE_M = (3.0, (0.3, 50.0))
NOISE_LEVEL = (0.01, (1e-5, 0.5))
#: An AP heard at fewer survey samples than this gets no model of its own (predicts 0).
MIN_SAMPLES_PER_AP = 5
#: The GP's mean function: the paper's zero, or a fitted log-distance path loss per AP.
MEANS = ("zero", "path_loss")


class PathLossMean:
    """Normalised signal ``(p0 - 10 n log10(max(d, 0.5 m)) + 100) / 100`` per AP, with the AP's
    position, ``p0`` and ``n`` fit to its heard samples (soft-L1 least squares); 0 for an AP
    heard too rarely."""

    def __init__(self, survey: Survey) -> None:
        self.params = np.full((survey.n_access_points, 4), np.nan)  # ax, ay, p0 (norm.), n
        for j in range(survey.n_access_points):
            heard = survey.signals[:, j] > 0
            if heard.sum() < MIN_SAMPLES_PER_AP:
                continue
            xy, z = survey.positions[heard], survey.signals[heard, j]
            start = np.r_[xy[np.argmax(z)], z.max(), 2.0]
            fit = least_squares(self._residual, start, loss="soft_l1", args=(xy, z))
            self.params[j] = fit.x

    @classmethod
    def _residual(cls, p: np.ndarray, xy: np.ndarray, z: np.ndarray) -> np.ndarray:
        return cls._curve(p, xy) - z

    @staticmethod
    def _curve(p: np.ndarray, xy: np.ndarray) -> np.ndarray:
        d = np.maximum(np.hypot(xy[:, 0] - p[0], xy[:, 1] - p[1]), 0.5)
        return p[2] - 0.1 * p[3] * np.log10(d / 0.5)

    def __call__(self, xy: np.ndarray) -> np.ndarray:
        """``(N, L)`` the curves at ``xy`` ``(N, 2)``, clipped to [0, 1]."""
        out = np.zeros((len(xy), len(self.params)))
        for j, p in enumerate(self.params):
            if np.isfinite(p).all():
                out[:, j] = np.clip(self._curve(p, xy), 0.0, 1.0)
        return out


def _regressor():
    from sklearn.gaussian_process import GaussianProcessRegressor
    from sklearn.gaussian_process.kernels import RBF, ConstantKernel, WhiteKernel

    kernel = ConstantKernel(0.1, (1e-3, 10.0)) * RBF(*LENGTH_SCALE_M) + WhiteKernel(*NOISE_LEVEL)
    return GaussianProcessRegressor(kernel=kernel, normalize_y=False, n_restarts_optimizer=0)


class SignalModel:
    """Predicted mean and variance of every AP's normalised signal at any location.

    Args:
        survey: The training survey (bin it first: :meth:`Survey.binned`).
        per_ap: True: mGP (a model per AP, only where it was heard); False: one GP for all.
        mean: ``"zero"`` (the paper's) or ``"path_loss"`` (ours: see the module doc).
    """

    def __init__(self, survey: Survey, per_ap: bool = True, mean: str = "zero") -> None:
        if mean not in MEANS:
            raise ConfigError(f"mean must be one of {MEANS}, got {mean!r}")
        self.per_ap = per_ap
        self.n_access_points = survey.n_access_points
        self.mean_function = PathLossMean(survey) if mean == "path_loss" else None
        heard_at = survey.signals > 0
        if self.mean_function is not None:  # the GPs learn what the curves leave
            survey = Survey(survey.positions, survey.signals - self.mean_function(survey.positions))
        self.models: list = []
        #: Each model's prior variance far from the data (σ_k² + σ_n²), for uint8 scaling.
        self.max_variance: list[float] = []
        with warnings.catch_warnings():  # bounds reached are fine: the fit says so in its kernel
            warnings.simplefilter("ignore")
            if per_ap:
                for j in range(self.n_access_points):
                    heard = heard_at[:, j]
                    if heard.sum() < MIN_SAMPLES_PER_AP:
                        self.models.append(None)
                        self.max_variance.append(1.0)
                        continue
                    gp = _regressor().fit(survey.positions[heard], survey.signals[heard, j])
                    self.models.append(gp)
                    self.max_variance.append(_prior_variance(gp))
            else:
                gp = _regressor().fit(survey.positions, survey.signals)
                self.models.append(gp)
                self.max_variance.append(_prior_variance(gp))

    def predict(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Mean and variance ``(N, L)`` at locations ``(N, 2)`` (direct GP prediction, Eqs. 8–9)."""
        xy = np.asarray(xy, np.float64).reshape(-1, 2)
        if not np.isfinite(xy).all():
            raise ConfigError("locations must be finite")
        mean = np.zeros((len(xy), self.n_access_points))
        var = np.ones((len(xy), self.n_access_points))
        if not self.per_ap:
            m, s = self.models[0].predict(xy, return_std=True)
            mean[:] = m.reshape(len(xy), -1)
            var[:] = (s**2).reshape(len(xy), -1)
        else:
            for j, gp in enumerate(self.models):
                if gp is not None:
                    m, s = gp.predict(xy, return_std=True)
                    mean[:, j], var[:, j] = m, s**2
        if self.mean_function is not None:
            mean += self.mean_function(xy)
        return mean, var


def _prior_variance(gp) -> float:
    """σ_k² + σ_n² of a fitted model: its variance far from any data."""
    params = gp.kernel_.get_params()
    return float(params["k1__k1__constant_value"] + params["k2__noise_level"])
