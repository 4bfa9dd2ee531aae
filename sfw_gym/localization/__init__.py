"""WiFi localisation from Gaussian gridmaps (Miyagusuku et al., "Gaussian Gridmaps from Gaussian
Processes for WiFi-based Robot Self-Localization"): a survey → GP signal models (GP or mGP) →
mean and variance gridmaps (float64, float16 or uint8, any resolution) → Monte-Carlo
localisation with the paper's sensor model, global localisation and kidnapping recovery."""

from __future__ import annotations

from sfw_gym.localization.gp import MEANS, SignalModel
from sfw_gym.localization.gridmaps import DTYPES, GaussianGridmaps
from sfw_gym.localization.mcl import MclConfig, WifiMCL, log_likelihood, low_variance_indices
from sfw_gym.localization.survey import Survey, normalise_rssi

__all__ = [
    "DTYPES",
    "MEANS",
    "GaussianGridmaps",
    "MclConfig",
    "SignalModel",
    "Survey",
    "WifiMCL",
    "log_likelihood",
    "low_variance_indices",
    "normalise_rssi",
]
