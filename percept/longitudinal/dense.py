"""Dense disparity of a rectified stereo pair: percept's dense mode and its peer, OpenCV's plain StereoSGBM.

percept's dense mode, in order:

1. Semi-global matching (Hirschmüller, PAMI 2008; OpenCV's ``StereoSGBM``, 3-way mode) of the left image against
   the right one and, through ``cv2.ximgproc.createRightMatcher``, of the right against the left, with the
   smoothness penalties of OpenCV's stereo_match sample (P1 = 8 cn b^2, P2 = 32 cn b^2 for block size b and cn
   channels). Both images are first padded on the left by the disparity range: StereoSGBM gives no value to the
   first ``num_disparities`` columns, and the padding lets it match every column whose partner is in view.
2. The weighted-least-squares filter of Min et al., "Fast global image smoothing based on weighted least
   squares", TIP 2014 (``cv2.ximgproc.createDisparityWLSFilter``): the left-right consistency of the two maps
   gives each pixel a confidence, and the disparities are smoothed along the left image's colours.
3. Holes left by the filter (occlusions, no confident neighbour) get the smaller of the nearest valid disparities
   left and right on their row: an occluded pixel belongs to the background.
4. Sub-pixel refinement (percept's own), ``refine_iterations`` times: one Lucas-Kanade step per pixel along the
   row (Lucas & Kanade, IJCAI 1981) on high-passed images, at most 0.25 px, then a bilateral filter of the
   disparities themselves (Tomasi & Manduchi, ICCV 1998; range sigma 1 px, so depth edges are not blurred). The
   step removes SGBM's pull of disparities towards whole pixels (its parabola fit on block costs), the filter
   the step's noise.

``row_misalignment_px`` measures how far a pair is from rectified: SIFT matches (Lowe, IJCV 2004), outliers
removed by a RANSAC fundamental matrix, median |row_left - row_right| of the rest.

Disparities are float32 [px] (d = x_left - x_right), NaN where there is no estimate.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Optional

import cv2
import numpy as np

MAX_DISPARITIES = 1024
MIN_MATCHES = 20
"""Fewer RANSAC-consistent feature matches than this: the rectification cannot be measured."""


def check_num_disparities(n: int) -> None:
    """OpenCV's matchers search a multiple of 16 disparities; ValueError naming the bad value otherwise."""
    if not (16 <= n <= MAX_DISPARITIES and n % 16 == 0):
        raise ValueError(f"num_disparities must be a multiple of 16 from 16 to {MAX_DISPARITIES}, got {n}")


@dataclass(frozen=True)
class DenseConfig:
    """Settings of percept's dense mode (see the module docstring for its steps)."""

    num_disparities: int = 64  # search range [px], a multiple of 16 from 16 to 1024 (disparities 0 .. n-1)
    block_size: int = 3  # matching block [px], odd, 1 to 11
    uniqueness_pct: int = 10  # how much the best cost must beat the second best [%], 0 to 100
    wls_lambda: float = 8000.0  # smoothness of the WLS filter (> 0)
    wls_sigma_color: float = 1.0  # the WLS filter's edge sensitivity (> 0)
    refine_iterations: int = 2  # sub-pixel steps (step 4), 0 to 10

    def __post_init__(self) -> None:
        check_num_disparities(self.num_disparities)
        if not (1 <= self.block_size <= 11 and self.block_size % 2 == 1):
            raise ValueError(f"block_size must be odd, 1 to 11, got {self.block_size}")
        if not 0 <= self.uniqueness_pct <= 100:
            raise ValueError(f"uniqueness_pct must be 0 to 100, got {self.uniqueness_pct}")
        if not (np.isfinite(self.wls_lambda) and self.wls_lambda > 0):
            raise ValueError(f"wls_lambda must be a finite number > 0, got {self.wls_lambda}")
        if not (np.isfinite(self.wls_sigma_color) and self.wls_sigma_color > 0):
            raise ValueError(f"wls_sigma_color must be a finite number > 0, got {self.wls_sigma_color}")
        if not 0 <= self.refine_iterations <= 10:
            raise ValueError(f"refine_iterations must be 0 to 10, got {self.refine_iterations}")


def default_num_disparities(width: int, ndisp: Optional[int] = None) -> int:
    """The search range for images ``width`` px wide: the calibration's ``ndisp`` when it gives one, else a sixth
    of the width (disparities of objects from about 3 baselines x focal/width away to infinity), rounded up to a
    multiple of 16 and kept within 16 .. 1024."""
    n = ndisp if ndisp is not None else width / 6.0
    return int(min(MAX_DISPARITIES, max(16, -(-int(np.ceil(n)) // 16) * 16)))


def check_pair(left: np.ndarray, right: np.ndarray) -> None:
    """ValueError unless both images have the same size and channels (uint8, gray or 3-channel)."""
    if left.shape != right.shape:
        raise ValueError(f"the images differ in size: left {left.shape[1]}x{left.shape[0]}, right "
                         f"{right.shape[1]}x{right.shape[0]} px; give a rectified pair of one size")
    if left.dtype != np.uint8 or left.ndim not in (2, 3):
        raise ValueError(f"expected 8-bit gray or colour images, got {left.dtype} of shape {left.shape}")


def _to_float(disp16: np.ndarray) -> np.ndarray:
    """OpenCV's fixed-point disparities (16 x px, int16, negative = invalid) -> float32 px, NaN invalid."""
    d = disp16.astype(np.float32) / 16.0
    d[disp16 < 0] = np.nan
    return d


def sgbm_disparity(left: np.ndarray, right: np.ndarray, num_disparities: int, block_size: int) -> np.ndarray:
    """The peer: ``cv2.StereoSGBM_create(0, num_disparities, block_size)`` with OpenCV's defaults otherwise,
    on the pair as it is. Float32 [px], NaN where it gives none."""
    check_pair(left, right)
    return _to_float(cv2.StereoSGBM_create(0, num_disparities, block_size).compute(left, right))


def sgbm_sample_disparity(left: np.ndarray, right: np.ndarray, num_disparities: int, block_size: int) -> np.ndarray:
    """A second peer: StereoSGBM with the settings of OpenCV's stereo_match sample (P1 = 8 cn b^2, P2 = 32 cn b^2,
    disp12MaxDiff 1, uniqueness 10 %, speckle window 100 px, speckle range 32), on the pair as it is."""
    check_pair(left, right)
    matcher = sample_sgbm(num_disparities, block_size, 1 if left.ndim == 2 else left.shape[2], disp12MaxDiff=1,
                          uniquenessRatio=10, speckleWindowSize=100, speckleRange=32)
    return _to_float(matcher.compute(left, right))


def sample_sgbm(num_disparities: int, block_size: int, channels: int = 1, **options) -> cv2.StereoSGBM:
    """StereoSGBM with OpenCV's sample smoothness penalties P1 = 8 cn b^2, P2 = 32 cn b^2 (and ``options``)."""
    b = block_size
    return cv2.StereoSGBM_create(0, num_disparities, b, P1=8 * channels * b * b, P2=32 * channels * b * b, **options)


def compare_methods(left: np.ndarray, right: np.ndarray, cfg: DenseConfig) -> dict[str, tuple[np.ndarray, float]]:
    """Each method's disparity [px] and wall time [ms] on this pair, in the same run: ``percept`` (dense mode),
    ``sgbm`` (plain StereoSGBM) and ``sgbm_sample`` (StereoSGBM, OpenCV sample settings); the same
    num_disparities and block_size for all."""
    runs = {"percept": lambda: dense_disparity(left, right, cfg),
            "sgbm": lambda: sgbm_disparity(left, right, cfg.num_disparities, cfg.block_size),
            "sgbm_sample": lambda: sgbm_sample_disparity(left, right, cfg.num_disparities, cfg.block_size)}
    out = {}
    for name, run in runs.items():
        t0 = time.perf_counter()
        d = run()
        out[name] = (d, 1000.0 * (time.perf_counter() - t0))
    return out


def _sgbm_wls(left: np.ndarray, right: np.ndarray, cfg: DenseConfig) -> np.ndarray:
    """Steps 1 and 2: padded left/right SGBM and the WLS filter with left-right confidence."""
    n = cfg.num_disparities
    matcher = sample_sgbm(n, cfg.block_size, 1 if left.ndim == 2 else left.shape[2], disp12MaxDiff=-1,
                          uniquenessRatio=cfg.uniqueness_pct, speckleWindowSize=0, mode=cv2.STEREO_SGBM_MODE_SGBM_3WAY)
    pad = [cv2.copyMakeBorder(im, 0, 0, n, 0, cv2.BORDER_REPLICATE) for im in (left, right)]
    d_left = matcher.compute(pad[0], pad[1])
    d_right = cv2.ximgproc.createRightMatcher(matcher).compute(pad[1], pad[0])
    wls = cv2.ximgproc.createDisparityWLSFilter(matcher)
    wls.setLambda(cfg.wls_lambda)
    wls.setSigmaColor(cfg.wls_sigma_color)
    return _to_float(wls.filter(d_left, pad[0], disparity_map_right=d_right)[:, n:])


def _high_pass(image: np.ndarray) -> np.ndarray:
    """Gray float32 minus its local mean (Gaussian, sigma 3 px): insensitive to a brightness offset between views."""
    g = (cv2.cvtColor(image, cv2.COLOR_BGR2GRAY) if image.ndim == 3 else image).astype(np.float32)
    return g - cv2.GaussianBlur(g, (0, 0), 3.0)


class _Aligner:
    """What the sub-pixel steps share for one pair, computed once: both views high-passed, the right view's row
    gradient and the pixel grid."""

    def __init__(self, left: np.ndarray, right: np.ndarray):
        self.lh, self.rh = _high_pass(left), _high_pass(right)
        # dR/dx by central differences (Sobel / 8: the smoothed derivative per pixel)
        self.grad = cv2.Sobel(self.rh, cv2.CV_32F, 1, 0, ksize=3) / 8.0
        h, w = self.lh.shape
        self.xs, self.ys = np.meshgrid(np.arange(w, dtype=np.float32), np.arange(h, dtype=np.float32))


def refine_subpixel(left: np.ndarray, right: np.ndarray, disparity: np.ndarray, window: int = 7,
                    max_step_px: float = 0.25, aligner: _Aligner | None = None) -> np.ndarray:
    """One Lucas-Kanade step along the rows: the shift delta that best aligns a ``window`` x ``window`` block of the
    right image, warped by the current disparity, with the left one; |delta| <= ``max_step_px``. NaN stays NaN.
    ``aligner``: the pair's shared terms, when several steps run on one pair."""
    a = aligner or _Aligner(left, right)
    lh, rh, grad, xs, ys = a.lh, a.rh, a.grad, a.xs, a.ys
    d = np.nan_to_num(disparity).astype(np.float32)
    # the right image seen from the left: R_w(x, y) = R(x - d, y), and its gradient G there
    warped = [cv2.remap(im, xs - d, ys, cv2.INTER_CUBIC, borderMode=cv2.BORDER_REPLICATE) for im in (rh, grad)]
    r_w, g = warped

    def box(a: np.ndarray) -> np.ndarray:
        return cv2.boxFilter(a, -1, (window, window))

    # R(x - d - delta) ~ R_w - G delta;  min_delta sum (R_w - G delta - L)^2  =>  delta = sum G (R_w - L) / sum G^2
    num, den = box(g * (r_w - lh)), box(g * g)
    delta = np.where(den > 1e-3, num / np.maximum(den, 1e-6), 0.0)
    out = d + np.clip(delta, -max_step_px, max_step_px)
    return np.where(np.isfinite(disparity), out, np.nan).astype(np.float32)


def fill_from_background(disparity: np.ndarray) -> np.ndarray:
    """Each NaN gets the smaller of the nearest finite disparities to its left and right on its row (an occluded
    pixel belongs to the farther surface); rows without any finite value stay NaN."""
    h, w = disparity.shape
    ok = np.isfinite(disparity)
    cols = np.arange(w)[None, :]
    left_idx = np.maximum.accumulate(np.where(ok, cols, -1), axis=1)
    right_idx = np.minimum.accumulate(np.where(ok, cols, w)[:, ::-1], axis=1)[:, ::-1]
    rows = np.arange(h)[:, None]
    from_left = np.where(left_idx >= 0, disparity[rows, np.clip(left_idx, 0, w - 1)], np.inf)
    from_right = np.where(right_idx < w, disparity[rows, np.clip(right_idx, 0, w - 1)], np.inf)
    filled = np.minimum(from_left, from_right)
    filled[np.isinf(filled)] = np.nan
    return np.where(ok, disparity, filled).astype(np.float32)


def smooth_disparity(disparity: np.ndarray, range_sigma_px: float = 1.0, space_sigma_px: float = 4.0) -> np.ndarray:
    """Bilateral filter of a disparity map on its own values (9 x 9 px): neighbours closer than about
    ``range_sigma_px`` in disparity are averaged, a depth edge is kept. NaN stays NaN and is not spread."""
    ok = np.isfinite(disparity)
    # w(p, q) = exp(-|p - q|^2 / 2 s_s^2) exp(-(d_p - d_q)^2 / 2 s_r^2)
    out = cv2.bilateralFilter(np.where(ok, disparity, 0.0).astype(np.float32), 9, range_sigma_px, space_sigma_px)
    return np.where(ok, out, np.nan).astype(np.float32)


def dense_disparity(left: np.ndarray, right: np.ndarray, cfg: DenseConfig = DenseConfig()) -> np.ndarray:
    """percept's dense disparity of the rectified pair (see the module docstring): float32 (H, W) [px], NaN where
    there is no estimate. ValueError for images of different sizes."""
    check_pair(left, right)
    d = fill_from_background(_sgbm_wls(left, right, cfg))
    aligner = _Aligner(left, right) if cfg.refine_iterations else None
    for _ in range(cfg.refine_iterations):
        d = smooth_disparity(refine_subpixel(left, right, d, aligner=aligner))
    return d


def row_misalignment_px(left: np.ndarray, right: np.ndarray, features: int = 2000) -> tuple[Optional[float], int]:
    """(median |row_left - row_right| [px] of the feature matches consistent with one epipolar geometry, their
    count); (None, count) when fewer than MIN_MATCHES remain. A rectified pair gives a few tenths of a pixel."""
    check_pair(left, right)
    sift = cv2.SIFT_create(features)
    gray = [cv2.cvtColor(im, cv2.COLOR_BGR2GRAY) if im.ndim == 3 else im for im in (left, right)]
    (kl, dl), (kr, dr) = (sift.detectAndCompute(g, None) for g in gray)
    if dl is None or dr is None or len(kl) < MIN_MATCHES or len(kr) < MIN_MATCHES:
        return None, 0
    matches = cv2.BFMatcher(cv2.NORM_L2, crossCheck=True).match(dl, dr)
    if len(matches) < MIN_MATCHES:
        return None, len(matches)
    pl = np.float32([kl[m.queryIdx].pt for m in matches])
    pr = np.float32([kr[m.trainIdx].pt for m in matches])
    # x_r^T F x_l = 0 for the inliers (Hartley & Zisserman, sec. 11.6); 1 px from the epipolar line
    _, mask = cv2.findFundamentalMat(pl, pr, cv2.FM_RANSAC, 1.0, 0.999)
    inliers = np.zeros(len(pl), bool) if mask is None else mask.ravel().astype(bool)
    if inliers.sum() < MIN_MATCHES:
        return None, int(inliers.sum())
    # the points are (u, v) = (col, row): compare v
    return float(np.median(np.abs(pl[inliers, 1] - pr[inliers, 1]))), int(inliers.sum())
