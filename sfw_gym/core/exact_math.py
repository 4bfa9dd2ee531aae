"""CPython's ``math.hypot`` and ``math.remainder``, compiled: the same bits inside numba kernels.

numba's own ``math.hypot`` calls the C library's, which differs from CPython's in the last bit
for about one pair in 200; these are CPython 3.11's algorithms (``Modules/mathmodule.c``:
``vector_norm`` with an error-free product, and ``m_remainder``), so that a compiled step gives
what the env's Python step gives, bit for bit (tests/core/test_exact_math.py).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

_VELTKAMP = 134217729.0  # 2**27 + 1: splits a double into two halves whose products are exact


@njit(cache=True, inline="always")
def _exact_product(x: float, y: float) -> tuple[float, float]:
    """``x * y`` as ``hi + lo`` exactly (Dekker's product)."""
    t = x * _VELTKAMP
    x_hi = t - (t - x)
    x_lo = x - x_hi
    t = y * _VELTKAMP
    y_hi = t - (t - y)
    y_lo = y - y_hi
    p = x_hi * y_hi
    q = x_hi * y_lo + x_lo * y_hi
    hi = p + q
    lo = p - hi + q + x_lo * y_lo
    return hi, lo


@njit(cache=True)
def hypot(x: float, y: float) -> float:
    """``math.hypot(x, y)`` exactly as CPython 3.11 computes it."""
    x = abs(x)
    y = abs(y)
    if math.isinf(x) or math.isinf(y):
        return math.inf
    if math.isnan(x) or math.isnan(y):
        return math.nan
    big = max(x, y)
    if big == 0.0:
        return big
    _, max_e = math.frexp(big)
    if max_e < -1023:  # subnormal: CPython rescales by DBL_MIN and recurses (never in a step)
        tiny = 2.2250738585072014e-308
        return tiny * hypot(x / tiny, y / tiny)
    scale = math.ldexp(1.0, -max_e)
    csum, frac1, frac2 = 1.0, 0.0, 0.0
    for v in (x, y):
        v *= scale
        hi, lo = _exact_product(v, v)
        s = csum + hi
        frac2 += hi - (s - csum)
        csum = s
        frac1 += lo
    h = math.sqrt(csum - 1.0 + (frac1 + frac2))
    hi, lo = _exact_product(-h, h)
    s = csum + hi
    frac2 += hi - (s - csum)
    csum = s
    frac1 += lo
    h += (csum - 1.0 + (frac1 + frac2)) / (2.0 * h)
    return h / scale


@njit(cache=True)
def remainder(x: float, y: float) -> float:
    """``math.remainder(x, y)`` for finite ``x`` and finite ``y`` ≠ 0 (exact, as CPython's)."""
    absx = abs(x)
    absy = abs(y)
    m = np.fmod(absx, absy)
    c = absy - m
    if m < c:
        r = m
    elif m > c:
        r = -c
    else:  # half-way: the even multiple
        r = m - 2.0 * np.fmod(0.5 * (absx - m), absy)
    return math.copysign(1.0, x) * r


@njit(cache=True)
def wrap_heading(theta: float) -> float:
    """``math.remainder(theta, math.tau)``: the angle in [-π, π], as the robot wraps its
    heading (not `sfw_gym.core.angles.wrap_angle`, which rounds differently in the last bit)."""
    return remainder(theta, 2.0 * math.pi)
