"""The compiled HOG blocks equal OpenCV's HOGDescriptor.compute to float32 rounding (every cell size the searches
use, colour and grey, sizes that are not whole blocks, flat and black images), and the weights they rely on."""

import cv2
import numpy as np
import pytest

from percept.detection.hog import hog_descriptor
from percept.detection.blocks import EPS_L2, L2HYS_CLIP, _blocks, axis_weights, gradients, hog_blocks


def opencv_blocks(image: np.ndarray, c: int) -> np.ndarray:
    """OpenCV's blocks: one window as large as the whole blocks of the image, its descriptor reshaped."""
    h, w = image.shape[:2]
    nbx, nby = (w - 2 * c) // c + 1, (h - 2 * c) // c + 1
    size = (2 * c + c * (nbx - 1), 2 * c + c * (nby - 1))
    d = hog_descriptor(size, c).compute(image, (c, c), (0, 0), [(0, 0)])
    return d.reshape(nbx, nby, 36)


def scene(h: int, w: int, seed: int, grey: bool = False) -> np.ndarray:
    """Smooth noise with hard-edged shapes on it (edges of every orientation, flat areas, saturated pixels)."""
    rng = np.random.default_rng(seed)
    img = cv2.GaussianBlur(rng.uniform(0, 255, (h, w, 3)).astype(np.uint8), (0, 0), 2.0)
    for _ in range(12):
        centre = (int(rng.integers(0, w)), int(rng.integers(0, h)))
        axes = (int(rng.integers(3, w // 3 + 4)), int(rng.integers(3, h // 3 + 4)))
        colour = tuple(int(x) for x in rng.integers(0, 256, 3))
        cv2.ellipse(img, centre, axes, float(rng.uniform(0, 180)), 0, 360, colour, -1)
    cv2.rectangle(img, (w // 4, h // 4), (w // 2, h // 2), (255, 255, 255), -1)
    return cv2.cvtColor(img, cv2.COLOR_BGR2GRAY) if grey else img


@pytest.mark.parametrize("c", [2, 4, 8])
@pytest.mark.parametrize("shape", [(100, 562), (131, 77), (480, 640), (37, 45)])
@pytest.mark.parametrize("grey", [False, True])
def test_blocks_equal_opencvs_to_float32_rounding(c, shape, grey):
    h, w = shape
    img = scene(h, w, seed=h * w + c, grey=grey)
    ref = opencv_blocks(img, c)
    got = hog_blocks(img, c)
    assert got.dtype == np.float32 and got.shape == ref.shape
    # the values are at most 0.2 / 0.2-ish after L2-Hys; a few units of float32's last place apart
    assert np.abs(got - ref).max() <= 1e-6
    assert np.abs(ref).max() > 0.1


def test_a_flat_or_black_image_has_empty_blocks_as_opencvs():
    for value in (0, 128, 255):
        img = np.full((64, 96, 3), value, np.uint8)
        got = hog_blocks(img, 4)
        assert np.array_equal(got, opencv_blocks(img, 4))
        assert not got.any()


def test_the_weights_vanish_where_the_kernel_skips_them():
    """The kernel skips X_1(d) for d < c/2 and X_0(d) for d >= 3c/2 (pixels beyond the cell centre on the far
    side); everywhere else both tents are positive where they overlap, and they sum to the Gaussian between the
    cell centres."""
    for c in (2, 4, 6, 8):
        x = axis_weights(c)
        d = np.arange(2 * c)
        assert x.shape == (2, 2 * c) and np.all(x >= 0)
        assert not x[1, d < c / 2].any() and not x[0, d >= 3 * c / 2].any()
        assert np.all(x[0, d < 3 * c / 2] > 0) and np.all(x[1, d >= c / 2] > 0)
        gauss = np.exp(-((d - c) ** 2) / (2 * (c / 2) ** 2))
        mid = (d >= c / 2) & (d < 3 * c / 2)
        assert np.allclose(x[0, mid] + x[1, mid], gauss[mid], rtol=1e-6)


def test_odd_or_tiny_cells_are_refused():
    img = scene(64, 64, seed=1)
    for c in (1, 3, 5):
        with pytest.raises(ValueError, match="even cell of at least 2 px"):
            hog_blocks(img, c)
    with pytest.raises(ValueError, match="smaller than one 16x16 px block"):
        hog_blocks(img[:15], 8)


def separable_blocks(mag: np.ndarray, bins: np.ndarray, c: int) -> np.ndarray:
    """The kernel's sums in numpy, each in the kernel's order: every pixel's two votes as a 9-bin vector, summed
    along x into each block column (dx ascending, from +0), the rows then along y into each block row (dy
    ascending), then L2-Hys with the sums of squares in four interleaved partial sums, (p0 + p1) + (p2 + p3).
    A zero weight or a bin a pixel does not vote into adds +0 here, which leaves a non-negative sum as it is."""
    h, w = mag.shape[:2]
    nbx, nby = (w - 2 * c) // c + 1, (h - 2 * c) // c + 1
    wx = axis_weights(c)
    yy, xx = np.mgrid[:h, :w]
    m = np.zeros((h, w, 9), np.float32)
    m[yy, xx, bins[..., 0]] = mag[..., 0]
    m[yy, xx, bins[..., 1]] = mag[..., 1]
    # R[y, bx, cx, bin] = sum_dx X_cx(dx) m[y, c bx + dx, bin]
    r = np.zeros((h, nbx, 2, 9), np.float32)
    for dx in range(2 * c):
        for cx in range(2):
            r[:, :, cx] += wx[cx, dx] * m[:, c * np.arange(nbx) + dx]
    # H[bx, by, cx, cy, bin] = sum_dy Y_cy(dy) R[c by + dy, bx, cx, bin]
    hist = np.zeros((nbx, nby, 2, 2, 9), np.float32)
    for dy in range(2 * c):
        for cy in range(2):
            hist[:, :, :, cy] += wx[cy, dy] * r[c * np.arange(nby) + dy].transpose(1, 0, 2, 3)
    v = hist.reshape(nbx, nby, 36)

    def norm(a):
        p = [a[..., k] * a[..., k] for k in range(4)]
        for i in range(4, 36):
            p[i % 4] = p[i % 4] + a[..., i] * a[..., i]
        return np.sqrt((p[0] + p[1]) + (p[2] + p[3]))

    t = np.minimum(v * (np.float32(1) / (norm(v) + EPS_L2))[..., None], np.float32(L2HYS_CLIP))
    return t * (np.float32(1) / (norm(t) + np.float32(1e-3)))[..., None]


@pytest.mark.parametrize("c", [2, 4, 8])
def test_blocks_equal_the_separable_sums_bit_for_bit(c):
    """The compiled pass against ``separable_blocks``: the same float32 operations in the same order give the same
    bits, on OpenCV's gradients of scenes and on random magnitudes (a third of them zero) and bins."""
    rng = np.random.default_rng(c)
    cases = [gradients(scene(h, w, seed=h + w + c), c) for h, w in [(100, 562), (131, 77), (2 * c, 2 * c)]]
    for h, w in [(37, 45), (64, 201), (2 * c + 1, 6 * c - 1)]:
        mag = rng.uniform(0, 300, (h, w, 2)).astype(np.float32)
        mag[rng.random((h, w)) < 0.3] = 0
        q = rng.integers(0, 9, (h, w))
        cases.append((mag, np.stack([q, (q + 1) % 9], -1).astype(np.uint8)))
    for mag, bins in cases:
        got = _blocks(mag, bins, c, axis_weights(c), np.float32(L2HYS_CLIP))
        ref = separable_blocks(mag, bins, c)
        assert got.shape == ref.shape and got.dtype == ref.dtype
        assert got.tobytes() == ref.tobytes()
        assert np.abs(ref).max() > 0.1
