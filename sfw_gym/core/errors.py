"""Exceptions raised on bad input: each names the input and the problem.

Every error of the package's own derives from :class:`SfwGymError` (catch that to catch them all);
each is also a ``ValueError``, as bad values are.
"""

from __future__ import annotations


class SfwGymError(ValueError):
    """Bad input to sfw_gym; the message names the input and the problem in one line."""


class FloorplanError(SfwGymError):
    """A floorplan file or geometry is malformed, or unusable for the simulation."""


class ConfigError(SfwGymError):
    """A configuration value, option or argument is invalid."""
