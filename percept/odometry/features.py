"""The pieces every visual odometry here shares: corners spread over the image, KLT tracking, pose covariance.

References: Rosten & Drummond 2006, "Machine learning for high-speed corner detection" (FAST); Bouguet 2000,
"Pyramidal implementation of the Lucas Kanade feature tracker"; Hartley & Zisserman, sec. 5.2 (covariance
of an estimate from the Jacobian of its cost).
"""

from __future__ import annotations

import cv2
import numpy as np

# below this mean intensity (or standard deviation) a frame has nothing to track: dark or featureless
MIN_CONTRAST_GREY = 2.0
# FAST's threshold is at least this many times the image's noise sigma (a corner must stand out of the noise)
NOISE_GAIN = 4.0
# Immerkaer's noise-estimation kernel, the difference of two Laplacians (blind to planes and ramps), is separable:
# [[1, -2, 1], [-2, 4, -2], [1, -2, 1]] = [1, -2, 1]^T [1, -2, 1]
_NOISE_TAPS = np.array([1, -2, 1], np.float32)


def noise_sigma(gray: np.ndarray) -> float:
    """The image noise's standard deviation [grey levels], robust to texture and edges: the median absolute
    response to Immerkaer's kernel, on every other pixel (Immerkaer 1996, "Fast noise variance estimation", CVIU
    64(2); the median in place of the mean keeps scene texture out)."""
    # integer taps on uint8: every response is a whole number within +-16 * 255, exact in int16
    r = np.abs(cv2.sepFilter2D(gray, cv2.CV_16S, _NOISE_TAPS, _NOISE_TAPS)[1:-1:2, 1:-1:2])
    if not r.size:
        return 0.0  # under 3 x 3 pixels: nothing to measure
    # the median from the histogram of |r|: the mean of the order statistics (n - 1) // 2 and n // 2, in float32
    # as numpy's median of the float32 responses gives it
    below = np.cumsum(np.bincount(r.ravel(), minlength=1))
    lo, hi = np.searchsorted(below, [(r.size - 1) // 2, r.size // 2], side="right")
    med = (np.float32(lo) + np.float32(hi)) / np.float32(2.0)
    # the kernel's gain on white noise is sqrt(36) = 6; 1.4826 MAD = sigma for a normal distribution
    return float(1.4826 * med / 6.0)


def check_intrinsics(K) -> np.ndarray:
    """K as a (3, 3) float array; ValueError unless it is finite with positive focal lengths."""
    K = np.asarray(K, dtype=np.float64)
    if K.shape != (3, 3) or not np.all(np.isfinite(K)) or K[0, 0] <= 0 or K[1, 1] <= 0:
        raise ValueError(f"K must be a finite (3, 3) intrinsic matrix with fx, fy > 0, got {K.tolist()}")
    return K


def detect_corners(gray: np.ndarray, max_corners: int, grid: tuple[int, int], threshold: int,
                   mask: np.ndarray | None = None, noise: float | None = None) -> np.ndarray:
    """FAST corners, the strongest few per grid cell so that they cover the image: (N, 2) float32 [px]. The
    threshold rises with the image noise (NOISE_GAIN sigma; ``noise``: sigma when already measured) so that noise
    makes no corners."""
    if float(cv2.meanStdDev(gray)[1][0, 0]) < MIN_CONTRAST_GREY:
        return np.zeros((0, 2), np.float32)
    threshold = max(int(threshold), int(round(NOISE_GAIN * (noise_sigma(gray) if noise is None else noise))))
    kps = cv2.FastFeatureDetector_create(threshold, True).detect(gray, mask)
    if not kps:
        return np.zeros((0, 2), np.float32)
    pts = cv2.KeyPoint_convert(kps).astype(np.float32).reshape(-1, 2)
    resp = np.float32([k.response for k in kps])
    h, w = gray.shape
    gx, gy = grid
    cell = (np.minimum(pts[:, 0] * gx // w, gx - 1) + gx * np.minimum(pts[:, 1] * gy // h, gy - 1)).astype(int)
    per_cell = max(1, int(np.ceil(max_corners / (gx * gy))))
    # strongest first, then the rank of each corner within its cell
    order = np.lexsort((-resp, cell))
    c_sorted = cell[order]
    first = np.searchsorted(c_sorted, c_sorted, side="left")
    rank = np.arange(len(order)) - first
    keep = order[rank < per_cell]
    keep = keep[np.argsort(-resp[keep])][:max_corners]
    return pts[keep]


def track(prev: np.ndarray, cur: np.ndarray, pts: np.ndarray, win_px: int, levels: int,
          guess: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """KLT from ``prev`` to ``cur``, starting from ``guess`` (N, 2) when given: the points' new positions (N, 2)
    float32 and which were tracked (N,) bool (found, and still inside the image)."""
    if len(pts) == 0:
        return np.zeros((0, 2), np.float32), np.zeros(0, bool)
    p0 = np.ascontiguousarray(pts, dtype=np.float32).reshape(-1, 1, 2)
    criteria = (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, 20, 0.03)
    if guess is None:
        p1, st, _err = cv2.calcOpticalFlowPyrLK(prev, cur, p0, None, winSize=(win_px, win_px), maxLevel=levels,
                                                criteria=criteria)
    else:
        p1, st, _err = cv2.calcOpticalFlowPyrLK(prev, cur, p0, np.ascontiguousarray(guess, np.float32).reshape(
            -1, 1, 2), winSize=(win_px, win_px), maxLevel=levels, criteria=criteria,
            flags=cv2.OPTFLOW_USE_INITIAL_FLOW)
    p1 = p1.reshape(-1, 2)
    h, w = cur.shape[:2]
    ok = (st.ravel() == 1) & np.all(np.isfinite(p1), axis=1)
    ok &= (p1[:, 0] >= 0) & (p1[:, 0] <= w - 1) & (p1[:, 1] >= 0) & (p1[:, 1] <= h - 1)
    return p1, ok


def pose_covariance(points: np.ndarray, pixels: np.ndarray, K: np.ndarray, rvec: np.ndarray,
                    tvec: np.ndarray) -> np.ndarray:
    """(6, 6) covariance of (rvec [rad], tvec [m]) of a PnP solution from its reprojection residuals."""
    proj, J = cv2.projectPoints(points, rvec, tvec, K, None)
    r = (proj.reshape(-1, 2) - pixels).ravel()
    J = J[:, :6]
    dof = max(len(r) - 6, 1)
    # sigma^2 = |r|^2 / (2N - 6); Sigma = sigma^2 (J^T J)^-1, with a floor of 0.1 px on sigma (subpixel limit)
    sigma2 = max(float(r @ r) / dof, 0.01)
    try:
        return sigma2 * np.linalg.inv(J.T @ J)
    except np.linalg.LinAlgError:
        return np.diag([1.0, 1.0, 1.0, 100.0, 100.0, 100.0])
