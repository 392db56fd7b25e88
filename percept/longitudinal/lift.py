"""Matched stereo pixels lifted to the vehicle frame in one compiled pass over the bands' disparity maps (the
finder's two bands into one set of arrays).

One pass instead of numpy's five passes and temporaries over a frame's matches (the mask of matched pixels, the
gathers of their columns, rows and rays, the depth, the range cut and the lift). The arithmetic is numpy's,
operation for operation and type for type, so the points are the same bit for bit as the numpy form kept as the
reference in tests/longitudinal/test_lift.py.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from percept.compiled import kernel


def lift_band(d16: np.ndarray, c0: int, skip: int, u: np.ndarray, v: np.ndarray, rays: np.ndarray, fb_scaled: float,
              z_min_m: float, z_max_m: float, origin: np.ndarray):
    """The matches of one band within the range (z_min_m, z_max_m), in row-major order.

    d16: (rows, c1 - c0) int16 StereoBM disparities (16 x pixels at the band's scale) of the band's columns c0..c1;
    skip: its first columns that had no room to search (left out); u, v: (rows, w) float32 full-resolution pixel
    centres of the band's pixels; rays: (rows, w, 3) float32 their rays in the vehicle frame; fb_scaled: f b x 16 x
    the band's scale, so that Z = fb_scaled / d16 [m]; origin: (3,) float64 the left camera in the vehicle frame [m].

    Returns u, v (N,) float32 [px], Z (N,) float32 [m] and the points (N, 3) float64 [m]: p = ray Z + origin.
    Comparisons and the depth are in float32 (numpy's rule for a Python float against a float32 array), the ray
    times the depth in float32 and the sum with the float64 origin in float64.
    """
    return lift_bands(((d16, c0, skip, u, v, rays, fb_scaled, 1.0), NO_BAND), z_min_m, z_max_m, origin)[:4]


NO_BAND = (np.zeros((0, 0), np.int16), 0, 0, np.zeros((0, 0), np.float32), np.zeros((0, 0), np.float32),
           np.zeros((0, 0, 3), np.float32), 1.0, 1.0)
"""A band without matches (``lift_bands``' second, for one band alone)."""


def lift_bands(bands, z_min_m: float, z_max_m: float, origin: np.ndarray):
    """``lift_band`` of two bands at once, into one set of arrays (the first band's matches, then the second's):
    ``bands``, two tuples (d16, c0, skip, u, v, rays, fb_scaled, area_px) with ``lift_band``'s arguments and the
    full-resolution pixels a match of the band stands for. Returns u, v, Z, points as ``lift_band`` and each match's
    area (N,) float32 [px]."""
    args = []
    for d16, c0, skip, u, v, rays, fb_scaled, area_px in bands:
        fits = d16.shape[0] == u.shape[0] and c0 + d16.shape[1] <= u.shape[1]
        if u.shape != v.shape or rays.shape != (*u.shape, 3) or not fits:
            raise ValueError(f"disparities {d16.shape} at column {c0} do not fit the band's pixels {u.shape} and rays "
                             f"{rays.shape}")
        args += [d16, int(c0), int(skip), u, v, rays, np.float32(fb_scaled), np.float32(area_px)]
    return _lift2(*args, np.float32(z_min_m), np.float32(z_max_m), np.asarray(origin, np.float64))


@kernel()
def _lift2(d16, c0, skip, u, v, rays, k, area, d16b, c0b, skipb, ub, vb, raysb, kb, areab, z_min, z_max,
           origin):  # pragma: no cover - compiled
    """``lift_bands``' arrays from the two bands' arguments, each band's matches counted first to size them."""
    n = _matched(d16, skip) + _matched(d16b, skipb)
    uo, vo, zo = np.empty(n, np.float32), np.empty(n, np.float32), np.empty(n, np.float32)
    po, ao = np.empty((n, 3), np.float64), np.empty(n, np.float32)
    m = _lift(d16, c0, skip, u, v, rays, k, area, z_min, z_max, origin, uo, vo, zo, po, ao, 0)
    m = _lift(d16b, c0b, skipb, ub, vb, raysb, kb, areab, z_min, z_max, origin, uo, vo, zo, po, ao, m)
    return uo[:m], vo[:m], zo[:m], po[:m], ao[:m]


@njit(cache=True)
def _matched(d16, skip):  # pragma: no cover - compiled
    """How many disparities of a band's searched columns are matches (> 0)."""
    rows, cols = d16.shape
    n = 0
    for r in range(rows):
        for j in range(skip, cols):
            if d16[r, j] > 0:
                n += 1
    return n


@njit(cache=True)
def _lift(d16, c0, skip, u, v, rays, k, area, z_min, z_max, origin, uo, vo, zo, po, ao,
          m):  # pragma: no cover - compiled
    """One band's matches in range written from index m on; the index after the last."""
    rows, cols = d16.shape
    for r in range(rows):
        for j in range(skip, cols):
            d = d16[r, j]
            if d <= 0:
                continue
            # Z = f b 16 s / d16
            z = k / np.float32(d)
            if not (z > z_min and z < z_max):
                continue
            x = c0 + j
            uo[m], vo[m], zo[m], ao[m] = u[r, x], v[r, x], z, area
            for a in range(3):
                # p = ray Z + origin: the product in float32, the sum in float64
                po[m, a] = np.float64(rays[r, x, a] * z) + origin[a]
            m += 1
    return m
