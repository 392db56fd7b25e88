"""Angle wrapping: a float and an array give the same bits."""

import math

import numpy as np

from percept.sensors import wrap_angle


def test_a_float_wraps_to_the_same_bits_as_an_array():
    rng = np.random.default_rng(0)
    x = np.concatenate([rng.uniform(-50, 50, 20000), rng.normal(0, 1e-9, 1000),
                        [math.pi, -math.pi, 3 * math.pi, 0.0, -0.0, 1e300, -1e-300]])
    as_array = wrap_angle(x)
    as_floats = np.array([wrap_angle(float(v)) for v in x])
    assert isinstance(wrap_angle(1.0), float)
    # both paths make the same IEEE operations (fmod is exact): the same bits on any CPU
    assert np.array_equal(as_array.view(np.int64), as_floats.view(np.int64))
    assert np.all((as_array >= -math.pi) & (as_array < math.pi))
    assert wrap_angle(3 * math.pi / 2) == -math.pi / 2
