"""The one angle wrap of the package, in Python and compiled alike."""

import math

import numpy as np
import pytest

from sfw_gym.core.angles import wrap_angle, wrap_angle_compiled


@pytest.mark.parametrize(
    ("a", "expected"),
    [(0.0, 0.0), (math.pi, -math.pi), (-math.pi, -math.pi), (3 * math.pi / 2, -math.pi / 2),
     (-5 * math.pi / 2, -math.pi / 2), (7.0, 7.0 - 2 * math.pi)],
)  # fmt: skip
def test_angles_wrap_to_minus_pi_pi_in_python_numpy_and_compiled_code(a, expected):
    assert wrap_angle(a) == pytest.approx(expected, abs=1e-12)
    assert wrap_angle_compiled(a) == wrap_angle(a)  # bit for bit
    np.testing.assert_array_equal(wrap_angle(np.array([a, a])), [wrap_angle(a)] * 2)
