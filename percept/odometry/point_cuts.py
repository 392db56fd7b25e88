"""The stereo VO's point cuts, each in one compiled pass: the points that agree with the motion prior, and the
points whose reprojection lies within a cut (with their gathers). Each gives numpy's arithmetic bit for bit
(tests/odometry/test_point_cuts.py)."""

from __future__ import annotations

import numpy as np

from percept.compiled import kernel


@kernel()
def within(seen, pixels, points, use, cut_px):  # pragma: no cover - compiled
    """The rows of ``use`` (N,), ``points`` (N, 3) and ``pixels`` (N, 2) float32 whose reprojection ``seen`` (N, 2)
    float64 lies closer than ``cut_px`` to the pixel, in one pass: numpy's
    ``keep = np.linalg.norm(seen - pixels, axis=1) < cut_px; use[keep], points[keep], pixels[keep]`` (the same
    arithmetic: float64 differences, two squares, one sum, sqrt)."""
    n = seen.shape[0]
    keep = np.empty(n, np.int64)
    m = 0
    for i in range(n):
        du = seen[i, 0] - np.float64(pixels[i, 0])
        dv = seen[i, 1] - np.float64(pixels[i, 1])
        if np.sqrt(du * du + dv * dv) < cut_px:
            keep[m] = i
            m += 1
    idx = np.empty(m, use.dtype)
    kept_points, kept_pixels = np.empty((m, 3), points.dtype), np.empty((m, 2), pixels.dtype)
    for j in range(m):
        i = keep[j]
        idx[j] = use[i]
        for k in range(3):
            kept_points[j, k] = points[i, k]
        kept_pixels[j, 0], kept_pixels[j, 1] = pixels[i, 0], pixels[i, 1]
    return idx, kept_points, kept_pixels


@kernel()
def agreeing(pixels, expected, kf_pixels, gate_px, gate_frac):  # pragma: no cover - compiled
    """Indices of the tracked ``pixels`` (N, 2) float32 that lie within gate_px + gate_frac x (their motion since the
    keyframe, from ``kf_pixels`` (N, 2) float32) of where the prior put them, ``expected`` (N, 2) float64: numpy's
    ``np.flatnonzero(norm(pixels - expected) < gate_px + gate_frac * norm(pixels - kf_pixels))`` with the same
    arithmetic: the offset in float64, the motion and the gate in float32 (numpy's type for a float32 array and
    Python floats)."""
    n = pixels.shape[0]
    g0, g1 = np.float32(gate_px), np.float32(gate_frac)
    out = np.empty(n, np.intp)
    m = 0
    for i in range(n):
        du = np.float64(pixels[i, 0]) - expected[i, 0]
        dv = np.float64(pixels[i, 1]) - expected[i, 1]
        fu = pixels[i, 0] - kf_pixels[i, 0]
        fv = pixels[i, 1] - kf_pixels[i, 1]
        flow = np.sqrt(fu * fu + fv * fv)
        if np.sqrt(du * du + dv * dv) < np.float64(g0 + g1 * flow):
            out[m] = i
            m += 1
    return out[:m]


def warm_up_cuts() -> None:
    """``within`` and ``agreeing`` loaded now on the argument types of a step (compiled once after an install),
    not in a frame."""
    within(np.zeros((0, 2)), np.zeros((0, 2), np.float32), np.zeros((0, 3)), np.zeros(0, np.intp), 1.0)
    agreeing(np.zeros((0, 2), np.float32), np.zeros((0, 2)), np.zeros((0, 2), np.float32), 3.0, 0.15)
