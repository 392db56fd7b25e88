"""The lane evidence's compiled top-hat and row maxima against numpy's formulas: the same responses, the same
points, bit for bit."""

import numpy as np
import pytest

from percept.lanes.evidence import _row_peaks, _top_hat


def _numpy_top_hat(centre, s, valid, min_contrast):
    resp = np.zeros_like(centre)
    inner = resp[:, s:-s]
    np.maximum(centre[:, :-2 * s], centre[:, 2 * s:], out=inner)
    np.subtract(centre[:, s:-s], inner, out=inner)
    resp *= valid
    return resp, resp[resp > min_contrast]


def _numpy_peaks(resp, thr):
    r, c = np.nonzero(resp[:, 1:-1] > thr)
    c += 1
    v = resp[r, c]
    keep = (v >= resp[r, c - 1]) & (v > resp[r, c + 1])
    return r[keep], c[keep]


@pytest.mark.parametrize("s", [2, 5])
def test_top_hat_and_row_maxima_equal_numpys(s):
    rng = np.random.default_rng(s)
    # box means of a dark road with bright stripes; plateaus (equal neighbours) test the >= / > asymmetry
    centre = rng.uniform(0, 60, (80, 120)).astype(np.float32)
    centre[:, 40:43] += 90
    centre[:, 90:92] = 150
    valid = (rng.random((80, 120)) < 0.9).astype(np.float32)
    # a Python float threshold compares in float32 (numpy's rule): 10.1 is not a float32
    resp, strong = _top_hat(centre, s, valid, np.float32(10.1))
    ref_resp, ref_strong = _numpy_top_hat(centre, s, valid, 10.1)
    assert resp.tobytes() == ref_resp.tobytes() and strong.tobytes() == ref_strong.tobytes()
    thr = 0.3 * float(np.partition(strong, int(0.9 * (strong.size - 1)))[int(0.9 * (strong.size - 1))])
    r, c = _row_peaks(resp, np.float32(thr))
    ref_r, ref_c = _numpy_peaks(ref_resp, thr)
    assert len(r) > 80
    # the compiled peaks compare the same float32 values as numpy does: the same peaks on any CPU
    assert np.array_equal(r, ref_r) and np.array_equal(c, ref_c) and r.dtype == ref_r.dtype


def test_no_response_above_an_infinite_threshold():
    resp, strong = _top_hat(np.zeros((10, 30), np.float32), 3, np.ones((10, 30), np.float32), np.float32(10))
    assert strong.size == 0
    r, c = _row_peaks(resp, np.float32(np.inf))
    assert r.size == 0 and c.size == 0
