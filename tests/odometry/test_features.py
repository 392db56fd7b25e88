import cv2
import numpy as np
import pytest

from percept.odometry.features import MIN_CONTRAST_GREY, detect_corners, noise_sigma

IMMERKAER = np.array([[1, -2, 1], [-2, 4, -2], [1, -2, 1]], np.float32)


def _textured(rng, sigma: float) -> np.ndarray:
    """A ramp, a bright square and checkers (structure the estimate must be blind to) plus Gaussian noise."""
    u, v = np.meshgrid(np.arange(320), np.arange(240))
    img = 40 + 0.3 * u + 0.2 * v
    img[60:140, 80:200] += 90
    img += 30 * (((u // 16) + (v // 16)) % 2)
    return np.clip(np.round(img + rng.normal(0, sigma, img.shape)), 0, 255).astype(np.uint8)


@pytest.mark.parametrize("sigma", [0.0, 2.0, 6.0])
def test_noise_sigma_is_immerkaers_median_estimate(sigma):
    img = _textured(np.random.default_rng(3), sigma)
    # the textbook form: the 3x3 kernel, every other pixel, numpy's median of the float32 responses
    r = cv2.filter2D(img, cv2.CV_32F, IMMERKAER)[1:-1:2, 1:-1:2]
    assert noise_sigma(img) == float(1.4826 * np.median(np.abs(r)) / 6.0)
    # and it measures the noise, not the scene (within rounding to whole grey levels)
    assert noise_sigma(img) == pytest.approx(sigma, abs=0.6)


def test_noise_sigma_of_a_tiny_or_flat_image_is_zero():
    assert noise_sigma(np.full((2, 2), 9, np.uint8)) == 0.0
    assert noise_sigma(np.full((40, 30), 9, np.uint8)) == 0.0


def test_a_flat_or_dark_frame_gives_no_corners():
    rng = np.random.default_rng(0)
    dim = np.clip(rng.normal(3, MIN_CONTRAST_GREY / 2, (120, 160)), 0, 255).astype(np.uint8)
    assert len(detect_corners(dim, 100, (4, 3), 5)) == 0
    assert len(detect_corners(_textured(rng, 1.0), 100, (4, 3), 5)) > 20


def test_a_spread_measured_already_decides_as_the_image_would():
    import cv2

    rng = np.random.default_rng(2)
    img = _textured(rng, 1.0)
    spread = float(cv2.meanStdDev(img)[1][0, 0])
    want = detect_corners(img, 100, (4, 3), 5)
    assert len(want) > 20 and np.array_equal(detect_corners(img, 100, (4, 3), 5, spread=spread), want)
    # told the image is flat, it finds nothing
    assert len(detect_corners(img, 100, (4, 3), 5, spread=MIN_CONTRAST_GREY / 2)) == 0
