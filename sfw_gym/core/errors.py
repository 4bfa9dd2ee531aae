"""Exceptions raised on bad input: each names the input and the problem."""

from __future__ import annotations


class FloorplanError(ValueError):
    """A floorplan file or geometry is malformed, or unusable for the simulation."""


class ConfigError(ValueError):
    """A configuration value, option or argument is invalid."""
