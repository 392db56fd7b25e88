"""The frame's percentiles and medians equal numpy's bit for bit (value and dtype)."""

import numpy as np
import pytest

from percept.longitudinal.quantiles import median, percentile, percentiles


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_percentiles_and_medians_equal_numpys(dtype):
    rng = np.random.default_rng(7)
    for n in list(range(1, 12)) + [99, 100, 801, 1600]:
        for rounded in (False, True):  # ties, as whole-pixel coordinates have
            a = (rng.normal(size=n) * 40).astype(dtype)
            a = np.round(a) if rounded else a
            for q in (0, 2, 5, 50, 98, 100):
                got, want = percentile(a, q), np.percentile(a, q)
                assert got == want and np.asarray(got).dtype == np.asarray(want).dtype
            got, want = percentiles(a, (2, 98)), np.percentile(a, [2, 98])
            assert list(got) == list(want) and all(np.asarray(g).dtype == want.dtype for g in got)
            got, want = median(a), np.median(a)
            assert got == want and np.asarray(got).dtype == np.asarray(want).dtype


def test_the_input_is_left_as_it_was():
    a = np.array([3.0, 1.0, 2.0, 5.0])
    percentile(a, 50), percentiles(a, (2, 98)), median(a)
    assert list(a) == [3.0, 1.0, 2.0, 5.0]


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_medians_of_signed_zeros_and_wide_values_equal_numpys(dtype):
    rng = np.random.default_rng(11)
    cases = [np.array(v, dtype) for v in ([-0.0], [-0.0, -0.0], [0.0, -0.0], [-0.0, 1.0, -0.0], [-1.0, 1.0])]
    for n in (1, 2, 3, 4, 7, 8):
        for _ in range(300):
            # magnitudes over many octaves: the sum of the middle two rounds
            cases.append((rng.normal(size=n) * rng.lognormal(0, 8, size=n)).astype(dtype))
    for a in cases:
        got, want = median(a), np.median(a)
        assert np.asarray(got).tobytes() == np.asarray(want).tobytes(), a
        assert np.asarray(got).dtype == np.asarray(want).dtype and type(got) is type(want)
