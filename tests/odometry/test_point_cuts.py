"""The stereo VO's compiled point cuts against numpy's formulas, made in the same operations: the same points, bit for bit at the gate."""

import numpy as np

from percept.odometry.point_cuts import agreeing, within


def _unit(rng, n):
    d = rng.normal(0, 1, (n, 2))
    return d / np.linalg.norm(d, axis=1)[:, None]


def test_within_equals_numpys_cut():
    rng = np.random.default_rng(3)
    for n in (0, 1, 50, 2000):
        pixels = rng.uniform(0, 640, (n, 2)).astype(np.float32)
        points = rng.normal(0, 10, (n, 3))
        use = np.sort(rng.choice(10 * n + 1, n, replace=False)).astype(np.intp)
        # half the reprojections exactly at the cut's distance (in float64), the rest anywhere near
        seen = pixels + np.where(rng.random((n, 1)) < 0.5, 0.7 * _unit(rng, n), rng.normal(0, 1, (n, 2)))
        keep = np.linalg.norm(seen - pixels, axis=1) < 0.7
        idx, kept_points, kept_pixels = within(seen, pixels, points, use, 0.7)
        for got, ref in ((idx, use[keep]), (kept_points, points[keep]), (kept_pixels, pixels[keep])):
            # the kernel's cut makes numpy's operations in its order: the same points on any CPU
            assert got.dtype == ref.dtype and np.array_equal(got, ref)


def test_agreeing_equals_numpys_gate():
    rng = np.random.default_rng(4)
    for n in (0, 1, 50, 2000):
        kf = rng.uniform(0, 640, (n, 2)).astype(np.float32)
        px = (kf + rng.normal(0, 20, (n, 2))).astype(np.float32)
        flow = np.linalg.norm(px - kf, axis=1)
        # offsets at the gate, 3 + 0.15 |motion| (float32, as numpy makes it), where float64 arithmetic would differ
        expected = px + (3.0 + 0.15 * flow).astype(np.float64)[:, None] * _unit(rng, n)
        ref = np.flatnonzero(np.linalg.norm(px - expected, axis=1) < 3.0 + 0.15 * flow)
        got = agreeing(px, expected, kf, 3.0, 0.15)
        assert got.dtype == ref.dtype and np.array_equal(got, ref)
