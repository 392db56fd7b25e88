"""A person's depth from the stereo pair: their head and torso in the left image matched along the same rows of the
right image (rectified rig), around the disparity their ground contact predicts.

Z = f b / d, so a disparity error sigma_d gives sigma_Z = Z^2 sigma_d / (f b): at 35 m (d = 8.5 px on the default
rig) 0.4 px, about what a small person patch matches to, is 4.7 % of the range, about what a detection window's
feet row gives (a pixel there is 4.5 %); the two are independent, so they are fused. The patch is the middle of
the box's width and its upper part (head and torso), so that the background beside the legs does not vote; the
cost is the sum of squared differences (``cv2.matchTemplate``), refined to a fraction of a pixel by a parabola
through the best cost and its neighbours.
"""

from __future__ import annotations

import math

import cv2
import numpy as np

from percept.compiled import kernel
from percept.sensors import StereoRig

SIGMA_D_PX = 0.4
"""Disparity noise of a matched person patch [px]."""
MIN_TEXTURE = 4.0
"""Smallest grey-level standard deviation of a patch worth matching."""


def _grey(image: np.ndarray) -> np.ndarray:
    return cv2.cvtColor(image, cv2.COLOR_BGR2GRAY) if image.ndim == 3 else image


def box_depth(left: np.ndarray, right: np.ndarray, box: tuple[float, float, float, float],
              rig: StereoRig, z_guess_m: float) -> tuple[float, float] | None:
    """Camera depth Z [m] and its standard deviation of the person in ``box`` (u0, v0, u1, v1) of the left image
    (the pair grey or BGR; only the patch and the strip it is searched along are made grey), searched between 0.6
    and 1.6 times the disparity of ``z_guess_m``; None when the patch is too small or featureless, or the match is
    not distinct."""
    h, w = left.shape[:2]
    u0, v0, u1, v1 = box
    bw, bh = u1 - u0, v1 - v0
    # head and torso, the middle half of the width
    pu0, pu1 = int(round(u0 + 0.25 * bw)), int(round(u1 - 0.25 * bw))
    pv0, pv1 = int(round(v0 + 0.05 * bh)), int(round(v0 + 0.6 * bh))
    if pu1 - pu0 < 3 or pv1 - pv0 < 6 or pu0 < 0 or pv0 < 0 or pu1 > w or pv1 > h:
        return None
    patch = _grey(left[pv0:pv1, pu0:pu1])
    # numpy's std decides only where the exact variance lies too near the threshold for its rounding
    side = texture_side(patch, MIN_TEXTURE * MIN_TEXTURE)
    if side < 0 or (side == 0 and float(patch.std()) < MIN_TEXTURE):
        return None
    fb = rig.camera.fx * rig.baseline_m
    d0 = fb / max(z_guess_m, 0.5)
    d_lo, d_hi = max(math.floor(0.6 * d0), 1), math.ceil(1.6 * d0) + 1
    # the right image's columns for disparities d_lo..d_hi: a point at u in the left is at u - d in the right
    s0, s1 = pu0 - d_hi, pu1 - d_lo
    if s0 < 0 or s1 > w:
        return None
    cost = cv2.matchTemplate(_grey(right[pv0:pv1, s0:s1]), patch, cv2.TM_SQDIFF).ravel()
    k, distinct = best_match(cost)
    if not distinct:
        return None
    c_m, c_0, c_p = float(cost[k - 1]), float(cost[k]), float(cost[k + 1])
    # parabola through the best cost and its neighbours: offset = (c- - c+) / (2 (c- - 2 c0 + c+))
    denom = c_m - 2 * c_0 + c_p
    sub = 0.5 * (c_m - c_p) / denom if denom > 0 else 0.0
    # position k in the strip is right column s0 + k, disparity d = pu0 - (s0 + k)
    d = pu0 - (s0 + k + sub)
    if d <= 0.5:
        return None
    z = fb / d
    # sigma_Z = Z^2 sigma_d / (f b)
    return z, z * z * SIGMA_D_PX / fb


@kernel()
def best_match(cost):  # pragma: no cover - compiled
    """The least of the costs (N,) float32 along the strip: its position k (the first of equal ones, as np.argmin)
    and whether the match is distinct: not at either end of the strip, and costing at most half the median
    (np.median's: the middle cost, or the float32 mean of the middle two)."""
    n = cost.shape[0]
    k = 0
    for i in range(1, n):
        if cost[i] < cost[k]:
            k = i
    if k == 0 or k == n - 1:
        return k, False
    s = np.sort(cost)
    # numpy's mean of the middle one or two: their float32 sum from +0, divided by their count
    median = (np.float32(0) + s[n // 2]) if n % 2 else (np.float32(0) + s[n // 2 - 1] + s[n // 2]) / np.float32(2)
    return k, not cost[k] > 0.5 * np.float64(median)


@kernel()
def texture_side(patch, var):  # pragma: no cover - compiled
    """Which side of ``var`` the variance of ``patch``'s grey levels (uint8 (h, w)) lies, from exact integer sums:
    -1 surely below, +1 surely above, 0 too near for np.std's rounding to be told apart. numpy's two-pass variance
    of such a patch is within ~1e-13 of the exact one (its sum of grey levels is exact, the mean and each square
    round at 1e-16, their pairwise sum at log2(n) 1e-16), far inside the 1e-9 kept here."""
    n, s, s2 = 0, 0, 0
    for i in range(patch.shape[0]):
        for j in range(patch.shape[1]):
            g = np.int64(patch[i, j])
            s += g
            s2 += g * g
            n += 1
    # n^2 var = n sum g^2 - (sum g)^2, exactly in integers
    v = (n * s2 - s * s) / (n * n)
    if v < var * (1 - 1e-9):
        return -1
    return 1 if v > var * (1 + 1e-9) else 0
