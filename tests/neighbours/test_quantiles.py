"""The detection's quantiles and medians against numpy's."""

import numpy as np

from percept.neighbours.quantiles import median, quantiles


def test_quantiles_are_numpys_bit_for_bit_and_of_its_dtype():
    rng = np.random.default_rng(0)
    for dtype in (np.float32, np.float64):
        for n in (1, 2, 3, 7, 50, 333):
            values = rng.normal(0.0, 5.0, n).astype(dtype)
            for q in ([0.1, 0.9], [0.05, 0.95], 0.95, 0.05, 0.5, [0.0, 1.0]):
                ours, theirs = np.asarray(quantiles(values, q)), np.asarray(np.quantile(values, q))
                assert ours.dtype == theirs.dtype and np.array_equal(ours, theirs)


def test_medians_are_numpys_bit_for_bit_and_of_its_dtype():
    rng = np.random.default_rng(1)
    for dtype in (np.float32, np.float64):
        for n in (1, 2, 3, 4, 7, 50, 333, 334):
            for _ in range(20):
                values = (rng.normal(0.0, 5.0, n) * rng.uniform(0.01, 100.0)).astype(dtype)
                ours, theirs = np.asarray(median(values)), np.asarray(np.median(values))
                assert ours.dtype == theirs.dtype and np.array_equal(ours, theirs)
