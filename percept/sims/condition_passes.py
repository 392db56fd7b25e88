"""The photometric conditions' per-pixel passes, compiled (numba, cached on disk): each fuses whole-image numpy and
OpenCV steps into one pass over the pixels, operation for operation in float32 as those steps computed, so that
the frames are the same bit for bit (``tests/sims/test_conditions_reference.py`` holds them to the plain numpy
formulas). ``conditions.py`` keeps the order of the steps, the random draws and what OpenCV does (blurs, lines).
"""

from __future__ import annotations

import numpy as np

from numba import njit

from percept.compiled import kernel

__all__ = ["beam_gain", "beam_spread", "glared", "hazy", "lit", "noisy_uint8", "through_drops", "with_noise_uint8"]


@njit(cache=True, inline="always")
def _byte(v):  # pragma: no cover - compiled
    """A float32 value clipped to 0..255 and truncated to uint8, as ``np.clip`` then ``astype(np.uint8)``."""
    return np.uint8(min(max(v, np.float32(0)), np.float32(255)))


@kernel()
def lit(img, gain, out):  # pragma: no cover - compiled
    """out (H, W, 3) float32 = img (H, W, 3) as float32 times gain (H, W) float32, channel by channel: the float32
    product numpy's broadcast (and OpenCV's ``multiply``) gives, without the float copy and the three-channel gain."""
    for y in range(img.shape[0]):
        for x in range(img.shape[1]):
            g = gain[y, x]
            for ch in range(3):
                out[y, x, ch] = np.float32(img[y, x, ch]) * g


@kernel()
def with_noise_uint8(out, noise, scale):  # pragma: no cover - compiled
    """uint8 (H, W, 3) of out (H, W, 3) float32 plus ``scale`` times the per-pixel ``noise`` (H, W) float32 on every
    channel, clipped to 0..255 and truncated: numpy's ``noise *= scale``, ``out += noise[..., None]``,
    ``np.clip(out, 0, 255)`` and ``astype(np.uint8)`` in one pass, each step in float32 as there."""
    res = np.empty(out.shape, np.uint8)
    for y in range(out.shape[0]):
        for x in range(out.shape[1]):
            a = noise[y, x] * scale
            for ch in range(3):
                res[y, x, ch] = _byte(out[y, x, ch] + a)
    return res


@kernel()
def beam_spread(inv, slope, cam_y, z, t):  # pragma: no cover - compiled
    """The night's beam before its exponential, per pixel in float32 as numpy's whole-array steps did: z = depth
    from 1/Z (``inv`` (H, W); inf for sky, capped at 1e4 m) and t = -spread^2, spread the lateral distance beyond
    1.5 m from the centreline over 0.3 Z + 1 (``slope`` (1, W): (u - cx) / fx; ``cam_y``: the camera's lateral
    offset [m])."""
    for y in range(inv.shape[0]):
        for x in range(inv.shape[1]):
            v = inv[y, x]
            # z = 1 / max(1/Z, 1e-6), inf for sky, capped at 1e4 m
            zv = np.float32(1.0) / max(v, np.float32(1e-6))
            if v <= 0:
                zv = np.float32(np.inf)
            zv = min(zv, np.float32(1e4))
            z[y, x] = zv
            # lateral distance from the centreline: y = y_cam - (u - cx) Z / fx
            d = abs(cam_y - slope[0, x] * zv)
            # spread = max(|y| - 1.5, 0) / (0.3 Z + 1)
            sp = max(d - np.float32(1.5), np.float32(0)) / (np.float32(0.3) * zv + np.float32(1.0))
            t[y, x] = -sp * sp


@kernel()
def beam_gain(z, t):  # pragma: no cover - compiled
    """The night's gain from t = exp(-spread^2) (in place): 0.08 + 1.1 beam, beam = t / (1 + (Z / 35)^2), none on
    the sky (Z at its 1e4 m cap), in float32 as numpy's whole-array steps did."""
    for y in range(z.shape[0]):
        for x in range(z.shape[1]):
            zv = z[y, x]
            q = zv / np.float32(35.0)
            b = t[y, x] / (q * q + np.float32(1.0))
            if zv >= np.float32(1e4):
                b = np.float32(0.0)
            t[y, x] = b * np.float32(1.1) + np.float32(0.08)


@kernel()
def hazy(blurred, scale, haze, streaks, out):  # pragma: no cover - compiled
    """The rain's veil in one pass: out (H, W, 3) float32 = blurred (H, W, 3) uint8 as float32 times ``scale``, plus
    ``haze`` (3,) per channel, plus ``streaks`` (H, W) on every channel, each step in float32 as numpy's and
    OpenCV's whole-image steps did."""
    for y in range(out.shape[0]):
        for x in range(out.shape[1]):
            s = streaks[y, x]
            for ch in range(3):
                out[y, x, ch] = (np.float32(blurred[y, x, ch]) * scale + haze[ch]) + s


@kernel()
def through_drops(out, d, blurred):  # pragma: no cover - compiled
    """Drops on the windscreen, in place: out = out (1 - 0.6 d) + 0.6 d ``blurred`` (out, blurred (H, W, 3), d (H, W),
    float32), each product and sum in float32 as OpenCV's whole-image steps did. Where d is 0 (most of the image)
    that is out x 1 + 0 x blurred = out (out >= 0, blurred finite), so those pixels are left as they are."""
    for y in range(out.shape[0]):
        for x in range(out.shape[1]):
            if d[y, x] == 0:
                continue
            a = d[y, x] * np.float32(0.6)
            keep = np.float32(1) - a
            for ch in range(3):
                out[y, x, ch] = out[y, x, ch] * keep + a * blurred[y, x, ch]


@kernel()
def glared(img, scale, lift, lit, out):  # pragma: no cover - compiled
    """The glare's wash in one pass: out (H, W, 3) float32 = (img (H, W, 3) uint8 as float32 times ``scale`` plus
    ``lift``) plus ``lit`` (H, W, 3) float32, each step in float32 as numpy's and OpenCV's whole-image steps did."""
    for y in range(out.shape[0]):
        for x in range(out.shape[1]):
            for ch in range(3):
                out[y, x, ch] = (scale * np.float32(img[y, x, ch]) + lift) + lit[y, x, ch]


@kernel()
def noisy_uint8(img, n, band):  # pragma: no cover - compiled
    """uint8 (H, W, 3) of img (H, W, 3) uint8 plus 10 ``n`` (H, W, 3) float32 plus the row's ``band`` (H, 1)
    float32, clipped to 0..255 and truncated: numpy's ``n *= 10``, ``n += img``, ``n += band`` by row, ``np.clip``
    and ``astype(np.uint8)`` in one pass, each step in float32 as there."""
    res = np.empty(img.shape, np.uint8)
    for y in range(img.shape[0]):
        b = band[y, 0]
        for x in range(img.shape[1]):
            for ch in range(3):
                res[y, x, ch] = _byte((n[y, x, ch] * np.float32(10.0) + np.float32(img[y, x, ch])) + b)
    return res
