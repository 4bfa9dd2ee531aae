"""The compiled hypot and remainder give CPython's bits (the batched step depends on it)."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from sfw_gym.core.exact_math import hypot, remainder, wrap_heading

finite = st.floats(allow_nan=False, allow_infinity=False)


def _bits(x: float) -> int:
    return int(np.float64(x).view(np.int64))


@settings(deadline=None)  # the first example compiles the kernel
@given(finite, finite)
def test_hypot_is_cpythons_to_the_bit(x, y):
    assert _bits(hypot(x, y)) == _bits(math.hypot(x, y))


def test_hypot_agrees_where_the_c_library_does_not():
    """Pairs where the C library's hypot (numba's own) differs from CPython's in the last bit."""
    rng = np.random.default_rng(0)
    xs, ys = rng.normal(0.0, 0.01, (2, 20_000)).tolist()
    assert all(hypot(x, y) == math.hypot(x, y) for x, y in zip(xs, ys, strict=True))
    assert hypot(math.inf, math.nan) == math.inf and math.isnan(hypot(1.0, math.nan))


@settings(deadline=None)
@given(finite, st.floats(min_value=1e-3, max_value=1e3))
def test_remainder_is_cpythons_to_the_bit(x, y):
    assert _bits(remainder(x, y)) == _bits(math.remainder(x, y))


def test_wrap_angle_is_the_robots_wrap_including_the_half_way_cases():
    angles = [k * math.pi for k in range(-9, 10)] + [-0.0, 0.0, 1e6, -3 * math.tau + 1e-12]
    for a in angles:
        assert _bits(wrap_heading(a)) == _bits(math.remainder(a, math.tau)), a
