"""sfw_gym: a Gymnasium environment for active WiFi exploration (Structure from WiFi)."""

from __future__ import annotations

from sfw_gym.errors import ConfigError, FloorplanError

__version__ = "0.1.0"

__all__ = ["ConfigError", "FloorplanError", "__version__"]
