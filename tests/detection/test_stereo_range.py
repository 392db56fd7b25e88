"""A person's stereo depth: a textured patch shifted by a known disparity is recovered to a fraction of a pixel;
featureless or ambiguous patches give nothing."""

import cv2
import numpy as np
import pytest

from percept.detection.stereo_range import box_depth
from percept.sensors import StereoRig


def pair(disparity_px: float, texture: bool = True):
    """A left image with a textured 'person' block on a textured background, the right image with the block
    shifted left by the disparity (the background at a fifth of it)."""
    rng = np.random.default_rng(3)
    # smooth texture, as a rendered or photographed surface has (white noise would lock to whole pixels)
    bg = cv2.GaussianBlur(rng.integers(40, 160, (480, 900)).astype(np.float32), (0, 0), 1.5)
    person = (cv2.GaussianBlur(rng.integers(0, 255, (120, 50)).astype(np.float32), (0, 0), 1.5) * 2 - 60
              if texture else np.full((120, 50), 90.0))
    left, right = bg[:, 100:740].copy(), np.empty((480, 640), np.float32)
    u = np.arange(640, dtype=np.float32)
    for v in range(480):  # the background further away: a fifth of the disparity
        right[v] = np.interp(u + disparity_px / 5, np.arange(900) - 100.0, bg[v])
    left[200:320, 300:350] = person
    xs = np.arange(50, dtype=np.float32)
    for v in range(120):
        right[200 + v, 280:360] = np.interp(np.arange(280, 360) + disparity_px - 300.0, xs, person[v])
    return left.astype(np.uint8), right.astype(np.uint8)


@pytest.mark.parametrize("d", [8.3, 14.6, 30.2])
def test_the_depth_of_a_shifted_patch(d):
    rig = StereoRig()
    fb = rig.camera.fx * rig.baseline_m
    left, right = pair(d)
    z, sigma = box_depth(left, right, (300.0, 200.0, 350.0, 320.0), rig, z_guess_m=fb / d * 1.2)
    assert fb / z == pytest.approx(d, abs=0.15)
    # sigma_Z = Z^2 sigma_d / (f b)
    assert sigma == pytest.approx(z * z * 0.4 / fb)


def test_featureless_or_out_of_image_patches_give_nothing():
    rig = StereoRig()
    left, right = pair(10.0, texture=False)
    assert box_depth(left, right, (300.0, 200.0, 350.0, 320.0), rig, 30.0) is None
    left, right = pair(10.0)
    assert box_depth(left, right, (-20.0, 200.0, 30.0, 320.0), rig, 30.0) is None
    assert box_depth(left, right, (300.0, 200.0, 302.0, 320.0), rig, 30.0) is None


def test_the_best_match_is_numpys_argmin_and_median_test():
    """``best_match`` gives np.argmin's position and the test box_depth made with np.median, on costs of odd and even
    lengths with ties, zeros and matchTemplate's slightly negative float32 rounding."""
    from percept.detection.stereo_range import best_match

    rng = np.random.default_rng(5)
    counts = np.zeros(3, int)  # distinct, at an end, not distinct enough
    for trial, n in enumerate(list(range(1, 12)) + [31, 40, 57, 64] * 30):
        kind = trial % 3
        if kind == 0:  # ties, zeros and tiny negatives
            cost = rng.choice([rng.uniform(0, 1e5), 0.0, -0.5, 7.0], n).astype(np.float32)
        elif kind == 1:  # a sharp minimum
            cost = (rng.uniform(0, 1e5, n) * rng.uniform(0, 1, n) ** 4).astype(np.float32)
        else:  # flat: the least cost near the median
            cost = rng.uniform(0.4e4, 1.1e4, n).astype(np.float32)
        k = int(np.argmin(cost))
        want = not (k == 0 or k == len(cost) - 1 or cost[k] > 0.5 * float(np.median(cost)))
        assert best_match(cost) == (k, want)
        counts[0 if want else 1 if k in (0, n - 1) else 2] += 1
    assert np.all(counts > 10), counts


def test_the_texture_test_decides_as_numpys_std_does():
    """``texture_side`` is -1 only where np.std is below the threshold and +1 only where it is not, and leaves the
    patches whose variance is the threshold's to np.std: random patches, patches at and about variance 16."""
    from percept.detection.stereo_range import MIN_TEXTURE, texture_side

    rng = np.random.default_rng(8)
    patches = [rng.integers(0, 256, (int(rng.integers(6, 200)), int(rng.integers(3, 120)))).astype(np.uint8) // d
               for d in rng.choice([1, 8, 16, 32, 64, 255], 300)]
    patches += [np.tile(np.array([0, 8], np.uint8), (6, 5)), np.tile(np.array([0, 8, 0, 9], np.uint8), (7, 3)),
                np.tile(np.array([1, 9, 1, 8], np.uint8), (7, 3)), np.full((9, 4), 200, np.uint8)]
    sides = []
    for p in patches:
        side = texture_side(p, MIN_TEXTURE * MIN_TEXTURE)
        below = float(p.std()) < MIN_TEXTURE
        assert side == 0 or (side < 0) == below
        sides.append(side)
    assert sides[-4] == 0 and sides.count(-1) > 20 and sides.count(1) > 20
