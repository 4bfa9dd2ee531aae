"""Angle wrapping, written once for the package (floats and numpy arrays alike)."""

from __future__ import annotations

from typing import TypeVar

import numpy as np
from numba import njit

A = TypeVar("A", float, np.ndarray)


def wrap_angle(a: A) -> A:
    """Angle(s) wrapped to [-π, π): ``(a + π) mod 2π − π``.

    The robot's own heading (``world.robot``) and the LiDAR gate use IEEE ``math.remainder``
    instead, which rounds differently in the last bit; they keep it so that the simulation's
    behaviour digest stays as recorded (compiled: `sfw_gym.core.exact_math.wrap_heading`).
    """
    return (a + np.pi) % (2.0 * np.pi) - np.pi


#: The same function, for compiled (numba) kernels.
wrap_angle_compiled = njit(cache=True)(wrap_angle)
