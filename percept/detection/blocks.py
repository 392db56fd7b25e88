"""Every HOG block of an image in one compiled pass, from OpenCV's gradients: the blocks OpenCV's
``HOGDescriptor.compute`` returns, to float32 rounding, reading each pixel once instead of once per block.

OpenCV's gradient (``HOGDescriptor.computeGradient``: the square-root gamma, the colour channel with the largest
gradient, each pixel's magnitude split between its two nearest of 9 orientation bins) is used as it is. What
OpenCV then does block by block — every pixel of a block (2c x 2c pixels, c the cell) voting into the four cells
about it with the block's Gaussian weight (sigma = c / 2, centred on the block's pixel (c, c)) times the bilinear
weight of the cell centres — is done here separably, because both weights are products of a weight along x and
one along y:

    H_b[cy, cx, bin] = sum_dy Y_cy(dy) sum_dx X_cx(dx) m_bin(y0 + dy, x0 + dx),
    X_k(d) = Y_k(d) = exp(-(d - c)^2 / (2 sigma^2)) max(0, 1 - |(d + 1/2) / c - 1/2 - k|)

Each image row is first summed along x into every block column (a pixel lies in two blocks and votes, for c even,
three of their four weights non-zero), then each row is added, weighted, into the two block rows that hold it;
each pixel is read once instead of once per block holding it (four times). Each block is then normalised as
OpenCV does (L2-Hys: L2 with an epsilon of 0.1 per value, clipped at 0.2, L2 again with 1e-3), its sums of
squares in four interleaved partial sums as OpenCV's own; a block row's histograms are kept value by value, the
blocks side by side, so that its norms are taken over all its blocks at once (as vectors). Only the order of the
float32 additions differs from OpenCV's, so the values differ from its by a few units of float32's last place
(``tests/detection/test_hog_blocks.py``).

Dalal & Triggs, "Histograms of Oriented Gradients for Human Detection", CVPR 2005 (the Gaussian block window and
the trilinear votes).
"""

from __future__ import annotations

from functools import lru_cache

import cv2
import numpy as np
from numba import njit

from percept.compiled import kernel

WINDOW_PX = (64, 128)
"""Detection window (width, height) [px]."""
CELL_PX = 8
"""HOG cell side at the window's own scale [px] (Dalal & Triggs 2005)."""
BINS = 9
L2HYS_CLIP = 0.2
"""OpenCV's default L2-Hys clipping threshold (that of its people detector, ``hog_descriptor``'s)."""
EPS_L2 = np.float32(np.float32(0.1) * np.float32(4 * BINS))
"""OpenCV's epsilon of the first L2 norm: 0.1 per value of the block, in float32."""


@lru_cache(maxsize=8)
def axis_weights(cell_px: int) -> np.ndarray:
    """(2, 2c) float32: X_k(d), the weight of the block's pixel d (along either axis) for its cell k (0, 1): the
    block's Gaussian (sigma = c / 2 about d = c, OpenCV's centring) times the tent of the cell centres."""
    c = int(cell_px)
    d = np.arange(2 * c, dtype=np.float32)
    sigma = np.float32(c / 2)
    # exp(-(d - c)^2 / (2 sigma^2))
    gauss = np.exp(-((d - np.float32(c)) ** 2) / (np.float32(2) * sigma * sigma))
    # the pixel's position in cells, from the first cell's centre: (d + 1/2) / c - 1/2
    cell = (d + np.float32(0.5)) / np.float32(c) - np.float32(0.5)
    tents = np.stack([np.maximum(np.float32(0), np.float32(1) - np.abs(cell - np.float32(k))) for k in (0, 1)])
    w = (tents * gauss).astype(np.float32)
    w.flags.writeable = False
    return w


def hog_descriptor(win_px: tuple[int, int] = WINDOW_PX, cell_px: int = CELL_PX) -> cv2.HOGDescriptor:
    """OpenCV's HOG with Dalal & Triggs' parameters (those of its default people detector) for windows of
    ``win_px`` (width, height) [px]: 8x8 cells, 16x16 blocks at an 8-pixel stride, 9 bins, L2-Hys at 0.2, gamma
    correction, the block's Gaussian weighting. ``cell_px`` other than 8 scales cells, blocks and stride together
    (a 4-pixel cell sees what an 8-pixel cell sees in the image enlarged twice)."""
    c = int(cell_px)
    return cv2.HOGDescriptor(win_px, (2 * c, 2 * c), (c, c), (c, c), BINS, 1, -1.0, cv2.HOGDescriptor_L2Hys,
                             L2HYS_CLIP, True, 64, False)


def gradients(image: np.ndarray, cell_px: int) -> tuple[np.ndarray, np.ndarray]:
    """OpenCV's HOG gradient of ``image`` (grey or BGR uint8): magnitudes (h, w, 2) float32 split between the two
    bins (h, w, 2) uint8 they vote into."""
    return _gradient_descriptor(int(cell_px)).computeGradient(image, None, None)


@lru_cache(maxsize=8)
def _gradient_descriptor(c: int) -> cv2.HOGDescriptor:
    """OpenCV's HOG with the people detector's parameters at cells of c px (its window does not matter here)."""
    return hog_descriptor((2 * c, 2 * c), c)


def hog_blocks(image: np.ndarray, cell_px: int) -> np.ndarray:
    """Every HOG block of ``image`` (at least 2c x 2c px): (nbx, nby, 36) float32, block (bx, by) at pixel
    (c bx, c by), its 36 values in OpenCV's order (cell x, cell y, bin)."""
    c = int(cell_px)
    if c < 2 or c % 2:
        raise ValueError(f"cells of {cell_px} px: the compiled HOG blocks need an even cell of at least 2 px")
    h, w = image.shape[:2]
    if h < 2 * c or w < 2 * c:
        raise ValueError(f"image of {w}x{h} px is smaller than one {2 * c}x{2 * c} px block")
    mag, bins = gradients(image, c)
    return _blocks(mag, bins, c, axis_weights(c), np.float32(L2HYS_CLIP))


@kernel()
def _blocks(mag, bins, c, wx, clip):  # pragma: no cover - compiled
    """Blocks (nbx, nby, 36) from magnitudes (h, w, 2) and bins (h, w, 2); wx: ``axis_weights(c)``."""
    h, w = mag.shape[0], mag.shape[1]
    nbx, nby = (w - 2 * c) // c + 1, (h - 2 * c) // c + 1
    out = np.empty((nbx, nby, 36), np.float32)
    # acc[by mod 2, 36 i + bx]: value i (OpenCV's order, 18 cx + 9 cy + bin) of block bx, unnormalised, in the two
    # block rows a pixel row feeds; a block row is normalised into ``out`` as soon as its last pixel row is in.
    # Value-major (the blocks of a row side by side), so that the norms below run over the blocks as vectors
    acc = np.empty((2, 36 * nbx), np.float32)
    row = np.empty((18, nbx), np.float32)
    scale1, scale2 = np.empty(nbx, np.float32), np.empty(nbx, np.float32)
    for y in range(nby * c + c):
        by = y // c
        if y % c == 0 and by < nby:
            acc[by % 2] = 0
        _row_sums(mag, bins, y, c, nbx, wx, row)
        _add_row(acc, row.reshape(18 * nbx), y, by, c, nby, nbx, wx)
        # block row by - 1 is complete after the last pixel row of cell row by
        done = by - 1
        if y % c == c - 1 and 0 <= done < nby:
            _normalise_row(acc[done % 2].reshape(36, nbx), clip, scale1, scale2, out, done)
    return out


@njit(cache=True, error_model="numpy", inline="always")
def _row_sums(mag, bins, y, c, nbx, wx, row):  # pragma: no cover - compiled
    """Pixel row y summed along x into every block column: row[9 cx + bin, bx] (18, nbx) float32."""
    half = c // 2
    # R[9 cx + bin, bx] = sum_dx X_cx(dx) m_bin(y, c bx + dx): pixel c j + e lies in blocks j (dx = e) and
    # j - 1 (dx = e + c); X_1(e) is zero for e < c/2 and X_0(e + c) for e >= c/2
    row[:] = 0
    for j in range(nbx + 1):
        p = j - 1
        for e in range(c):
            x = c * j + e
            g0, g1 = mag[y, x, 0], mag[y, x, 1]
            q0, q1 = np.int64(bins[y, x, 0]), np.int64(bins[y, x, 1])
            if j < nbx:
                wt = wx[0, e]
                row[q0, j] += wt * g0
                row[q1, j] += wt * g1
                if e >= half:
                    wt = wx[1, e]
                    row[9 + q0, j] += wt * g0
                    row[9 + q1, j] += wt * g1
            if j >= 1:
                if e < half:
                    wt = wx[0, e + c]
                    row[q0, p] += wt * g0
                    row[q1, p] += wt * g1
                wt = wx[1, e + c]
                row[9 + q0, p] += wt * g0
                row[9 + q1, p] += wt * g1


@njit(cache=True, error_model="numpy", inline="always")
def _add_row(acc, r, y, by, c, nby, nbx, wx):  # pragma: no cover - compiled
    """Pixel row y's column sums ``r`` (18 nbx,) added, weighted along y, into the block rows that hold it."""
    # H[by, cy] += Y_cy(dy) R for the block rows by = y // c (dy = y mod c) and by - 1 (dy + c)
    for k in range(2):
        b = by - k
        if b < 0 or b >= nby:
            continue
        dy = y - c * by + c * k
        a = acc[b % 2]
        for cy in range(2):
            wt = wx[cy, dy]
            # X_1(dy) = 0 for dy < c/2 and X_0(dy) = 0 for dy >= 3c/2: the +0 those rows would add to the
            # (non-negative) sums leaves them as they are, so one of the four (k, cy) is skipped in every row
            if wt == 0:
                continue
            for cx in range(2):
                o, src = (18 * cx + 9 * cy) * nbx, 9 * cx * nbx
                for m in range(9 * nbx):
                    a[o + m] += wt * r[src + m]


@njit(cache=True, error_model="numpy", inline="always")
def _normalise_row(v, clip, scale1, scale2, out, done):  # pragma: no cover - compiled
    """Block row ``done``'s sums ``v`` (36, nbx) normalised (L2-Hys) in place and written to out[:, done]."""
    nbx = v.shape[1]
    _l2hys_scales(v, clip, scale1, scale2)
    # v <- min(v scale1, clip) scale2 in place, over the blocks as vectors; then each block's 36 values out
    for i in range(36):
        for bx in range(nbx):
            t = v[i, bx] * scale1[bx]
            v[i, bx] = (t if t < clip else clip) * scale2[bx]
    for bx in range(nbx):
        for i in range(36):
            out[bx, done, i] = v[i, bx]


@njit(cache=True, error_model="numpy", inline="always")
def _l2hys_scales(v, clip, scale1, scale2):
    """L2-Hys's two scales of each block (column) of ``v`` (36, n): scale1 = 1 / (|v| + 0.1 * 36), then, of the
    values clipped, min(v scale1, clip), scale2 = 1 / (|.| + 1e-3); each sum of squares in four interleaved partial
    sums, (p0 + p1) + (p2 + p3), OpenCV's order. Each loop runs over the blocks, as vectors."""
    n = v.shape[1]
    for b in range(n):
        p0, p1, p2, p3 = v[0, b] * v[0, b], v[1, b] * v[1, b], v[2, b] * v[2, b], v[3, b] * v[3, b]
        for i in range(4, 36, 4):
            p0 += v[i, b] * v[i, b]
            p1 += v[i + 1, b] * v[i + 1, b]
            p2 += v[i + 2, b] * v[i + 2, b]
            p3 += v[i + 3, b] * v[i + 3, b]
        scale1[b] = np.float32(1) / (np.sqrt((p0 + p1) + (p2 + p3)) + EPS_L2)
    for b in range(n):
        s = scale1[b]
        t0, t1, t2, t3 = min(v[0, b] * s, clip), min(v[1, b] * s, clip), min(v[2, b] * s, clip), min(v[3, b] * s, clip)
        p0, p1, p2, p3 = t0 * t0, t1 * t1, t2 * t2, t3 * t3
        for i in range(4, 36, 4):
            t0, t1 = min(v[i, b] * s, clip), min(v[i + 1, b] * s, clip)
            t2, t3 = min(v[i + 2, b] * s, clip), min(v[i + 3, b] * s, clip)
            p0 += t0 * t0
            p1 += t1 * t1
            p2 += t2 * t2
            p3 += t3 * t3
        scale2[b] = np.float32(1) / (np.sqrt((p0 + p1) + (p2 + p3)) + np.float32(1e-3))
