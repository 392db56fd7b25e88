"""The odometry's compiled noise estimate and corner selection against numpy's formulas, made in the same operations: the same values."""

import cv2
import numpy as np
import pytest

from percept.compiled import floor_quotient
from percept.odometry.features import _strongest_per_cell, noise_sigma

_TAPS = np.array([1, -2, 1], np.float32)


def _numpy_noise_sigma(gray):
    r = np.abs(cv2.sepFilter2D(gray, cv2.CV_16S, _TAPS, _TAPS)[1:-1:2, 1:-1:2])
    if not r.size:
        return 0.0
    below = np.cumsum(np.bincount(r.ravel(), minlength=1))
    lo, hi = np.searchsorted(below, [(r.size - 1) // 2, r.size // 2], side="right")
    return float(1.4826 * ((np.float32(lo) + np.float32(hi)) / np.float32(2.0)) / 6.0)


@pytest.mark.parametrize("shape", [(2, 9), (3, 3), (4, 6), (57, 101), (480, 640)])
def test_noise_sigma_equals_numpys(shape):
    rng = np.random.default_rng(shape[0])
    flat = np.full(shape, 90, np.uint8)
    ramp = np.tile(np.arange(shape[1], dtype=np.uint8), (shape[0], 1))
    noisy = np.clip(120 + rng.normal(0, 7, shape), 0, 255).astype(np.uint8)
    extreme = rng.choice(np.array([0, 255], np.uint8), shape)
    for gray in (flat, ramp, noisy, extreme):
        assert noise_sigma(gray) == _numpy_noise_sigma(gray)
    assert shape[0] < 100 or abs(noise_sigma(noisy) - 7.0) < 1.0


def _numpy_strongest(pts, resp, gx, gy, w, h, per_cell):
    cell = (np.minimum(pts[:, 0] * gx // w, gx - 1) + gx * np.minimum(pts[:, 1] * gy // h, gy - 1)).astype(int)
    order = np.lexsort((-resp, cell))
    c_sorted = cell[order]
    rank = np.arange(len(order)) - np.searchsorted(c_sorted, c_sorted, side="left")
    return order[rank < per_cell]


def test_strongest_per_cell_equals_lexsorts_cut():
    rng = np.random.default_rng(5)
    for n in (0, 1, 7, 300, 4600):
        # whole-number responses (FAST's scores) tie often: ties go to the lower index, as in numpy's stable sort
        pts = np.column_stack([rng.uniform(0, 639.9, n), rng.uniform(0, 479.9, n)]).astype(np.float32)
        pts[: n // 10, 0] = 64.0 * rng.integers(0, 10, n // 10)  # on cell borders
        resp = rng.integers(5, 40, n).astype(np.float32)
        for per_cell in (1, 7):
            got = _strongest_per_cell(pts, resp, 10, 6, 640, 480, per_cell)
            ref = _numpy_strongest(pts, resp, 10, 6, 640, 480, per_cell)
            assert got.dtype == ref.dtype and np.array_equal(got, ref)


def test_floor_quotient_equals_numpys_floor_division():
    rng = np.random.default_rng(7)
    # a corner's cell: u gx // w in float32, u over the image and beyond, at the cell borders and just beside them
    for w, gx in ((640, 10), (480, 6)):
        a = (np.float32(gx) * rng.uniform(-5.0, w + 5.0, 20000).astype(np.float32)).astype(np.float32)
        borders = np.float32(w) * np.arange(-1, gx + 2, dtype=np.float32)
        a = np.concatenate([a, borders, np.nextafter(borders, np.float32(-np.inf)),
                            np.nextafter(borders, np.float32(np.inf))])
        ref = (a // np.float32(w)).astype(np.int64)
        assert [floor_quotient(x, np.float32(w)) for x in a] == ref.tolist()
