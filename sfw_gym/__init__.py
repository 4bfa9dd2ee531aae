"""sfw_gym: a Gymnasium environment for active WiFi exploration (Structure from WiFi).

``import sfw_gym`` registers the environments (``gym.make("SfW-Explore-v0")``).
"""

from __future__ import annotations

from sfw_gym.core.errors import ConfigError, FloorplanError, SfwGymError
from sfw_gym.envs import ENV_IDS, register_envs

__version__ = "0.2.0"

register_envs()

__all__ = ["ENV_IDS", "ConfigError", "FloorplanError", "SfwGymError", "__version__"]
