"""The face's subpixel disparity on a synthetic pair: a textured plane shifted by a known disparity."""

import cv2
import numpy as np
import pytest

from percept.neighbours import refine_face
from percept.neighbours.refine import INTERPOLATION_BIAS_PX


def _pair(d_px: float, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """A smooth random texture (left) and the same shifted left by d_px along the rows (right): L(u) = R(u - d)."""
    rng = np.random.default_rng(seed)
    tex = cv2.GaussianBlur(rng.uniform(0, 255, (60, 200)).astype(np.float32), (0, 0), 1.5)
    u = np.arange(200, dtype=np.float32)
    # R(u) = L(u + d)
    mapx = np.tile(u + np.float32(d_px), (60, 1))
    mapy = np.tile(np.arange(60, dtype=np.float32)[:, None], (1, 200))
    right = cv2.remap(tex, mapx, mapy, cv2.INTER_CUBIC)
    return np.clip(tex, 0, 255).astype(np.uint8), np.clip(right, 0, 255).astype(np.uint8)


@pytest.mark.parametrize("d_px", [6.23, 11.5, 20.81])
def test_recovers_a_known_subpixel_disparity(d_px):
    left, right = _pair(d_px)
    v, u = np.mgrid[10:50, 60:160]
    out = refine_face(left, right, u.ravel(), v.ravel(), round(d_px))
    assert out is not None
    d, sigma = out
    # linear interpolation leaves up to INTERPOLATION_BIAS_PX at fractional shifts, and sigma says so
    assert abs(d - d_px) <= INTERPOLATION_BIAS_PX
    assert sigma == pytest.approx(INTERPOLATION_BIAS_PX)


def test_a_flat_patch_or_too_few_pixels_cannot_be_aligned():
    flat = np.full((60, 200), 128, np.uint8)
    v, u = np.mgrid[10:50, 60:160]
    assert refine_face(flat, flat, u.ravel(), v.ravel(), 8.0) is None
    left, right = _pair(8.0)
    assert refine_face(left, right, np.array([70, 71]), np.array([20, 20]), 8.0) is None
