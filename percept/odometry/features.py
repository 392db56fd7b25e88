"""The pieces every visual odometry here shares: corners spread over the image, KLT tracking, pose covariance.

References: Rosten & Drummond 2006, "Machine learning for high-speed corner detection" (FAST); Bouguet 2000,
"Pyramidal implementation of the Lucas Kanade feature tracker"; Hartley & Zisserman, sec. 5.2 (covariance
of an estimate from the Jacobian of its cost).
"""

from __future__ import annotations

from operator import attrgetter

import cv2
import numpy as np
from numba import njit

from percept.compiled import floor_quotient, kernel

# below this mean intensity (or standard deviation) a frame has nothing to track: dark or featureless
MIN_CONTRAST_GREY = 2.0
# FAST's threshold is at least this many times the image's noise sigma (a corner must stand out of the noise)
NOISE_GAIN = 4.0
_RESPONSE = attrgetter("response")  # a keypoint's FAST score


def noise_sigma(gray: np.ndarray) -> float:
    """The noise's standard deviation [grey levels] of ``gray`` ((H, W) uint8), robust to texture and edges: the
    median absolute response to Immerkaer's kernel, on every other pixel (Immerkaer 1996, "Fast noise variance
    estimation", CVIU 64(2); the median in place of the mean keeps scene texture out)."""
    if gray.shape[0] < 3 or gray.shape[1] < 3:
        return 0.0  # under 3 x 3 pixels: nothing to measure
    # the median of |r| from its histogram: the mean of the order statistics (n - 1) // 2 and n // 2, in float32 as
    # numpy's median of the float32 responses gives it
    lo, hi = _noise_median_ranks(np.ascontiguousarray(gray, np.uint8))
    med = (np.float32(lo) + np.float32(hi)) / np.float32(2.0)
    # the kernel's gain on white noise is sqrt(36) = 6; 1.4826 MAD = sigma for a normal distribution
    return float(1.4826 * med / 6.0)


@njit(cache=True)
def _row_second_difference(gray, y, out):  # pragma: no cover - compiled
    """out[j] = g(y, x - 1) - 2 g(y, x) + g(y, x + 1) at the odd columns x = 2 j + 1 of the uint8 image g."""
    for j in range(out.shape[0]):
        x = 2 * j + 1
        out[j] = np.int32(gray[y, x - 1]) - 2 * np.int32(gray[y, x]) + np.int32(gray[y, x + 1])


@kernel()
def _noise_median_ranks(gray):  # pragma: no cover - compiled
    """The values of order (n - 1) // 2 and n // 2 of |r| over every other interior pixel (rows and columns 1, 3, ...
    up to the last but one), r the response to Immerkaer's kernel, the difference of two Laplacians (blind to planes
    and ramps), [[1, -2, 1], [-2, 4, -2], [1, -2, 1]] = [1, -2, 1]^T [1, -2, 1]: whole numbers within +-16 * 255 (what
    ``cv2.sepFilter2D`` gave in int16), counted in a histogram."""
    h, w = gray.shape
    # separable: r = t(y - 1) - 2 t(y) + t(y + 1) with the row's second difference t = g(x - 1) - 2 g(x) + g(x + 1) at
    # the odd columns; the even row below a sampled row is the one above the next
    m = (w - 1) // 2
    above, mid, below, r = np.empty(m, np.int32), np.empty(m, np.int32), np.empty(m, np.int32), np.empty(m, np.int32)
    # four histograms, counted in turn (most responses fall in the few lowest bins: one histogram would wait on its
    # own last increment), added up as the ranks are searched
    counts = np.zeros((4, 16 * 255 + 1), np.int64)
    n = 0
    _row_second_difference(gray, 0, above)
    for y in range(1, h - 1, 2):
        _row_second_difference(gray, y, mid)
        _row_second_difference(gray, y + 1, below)
        for j in range(m):
            r[j] = abs(above[j] - 2 * mid[j] + below[j])
        j = 0
        while j + 4 <= m:
            counts[0, r[j]] += 1
            counts[1, r[j + 1]] += 1
            counts[2, r[j + 2]] += 1
            counts[3, r[j + 3]] += 1
            j += 4
        for k in range(j, m):
            counts[0, r[k]] += 1
        n += m
        above, below = below, above
    lo_rank, hi_rank = (n - 1) // 2, n // 2
    lo = hi = -1
    seen = 0
    for v in range(counts.shape[1]):
        seen += counts[0, v] + counts[1, v] + counts[2, v] + counts[3, v]
        # searchsorted(cumulative counts, rank, side="right"): the first value whose cumulative count exceeds rank
        if lo < 0 and seen > lo_rank:
            lo = v
        if seen > hi_rank:
            hi = v
            break
    return lo, hi


def check_intrinsics(K) -> np.ndarray:
    """K as a (3, 3) float array; ValueError unless it is finite with positive focal lengths."""
    K = np.asarray(K, dtype=np.float64)
    if K.shape != (3, 3) or not np.all(np.isfinite(K)) or K[0, 0] <= 0 or K[1, 1] <= 0:
        raise ValueError(f"K must be a finite (3, 3) intrinsic matrix with fx, fy > 0, got {K.tolist()}")
    return K


def detect_corners(gray: np.ndarray, max_corners: int, grid: tuple[int, int], threshold: int,
                   mask: np.ndarray | None = None, noise: float | None = None,
                   spread: float | None = None) -> np.ndarray:
    """FAST corners, the strongest few per grid cell so that they cover the image: (N, 2) float32 [px]. The
    threshold rises with the image noise (NOISE_GAIN sigma; ``noise``: sigma when already measured) so that noise
    makes no corners; none in an image whose grey levels' standard deviation (``spread``, when already measured)
    is under MIN_CONTRAST_GREY."""
    if (float(cv2.meanStdDev(gray)[1][0, 0]) if spread is None else spread) < MIN_CONTRAST_GREY:
        return np.zeros((0, 2), np.float32)
    threshold = max(int(threshold), int(round(NOISE_GAIN * (noise_sigma(gray) if noise is None else noise))))
    kps = cv2.FastFeatureDetector_create(threshold, True).detect(gray, mask)
    if not kps:
        return np.zeros((0, 2), np.float32)
    pts = cv2.KeyPoint_convert(kps).astype(np.float32).reshape(-1, 2)
    resp = np.fromiter(map(_RESPONSE, kps), np.float32, len(kps))
    h, w = gray.shape
    gx, gy = grid
    per_cell = max(1, int(np.ceil(max_corners / (gx * gy))))
    keep = _strongest_per_cell(pts, resp, gx, gy, w, h, per_cell)
    keep = keep[np.argsort(-resp[keep])][:max_corners]
    return pts[keep]


@kernel()
def _strongest_per_cell(pts, resp, gx, gy, w, h, per_cell):  # pragma: no cover - compiled
    """Indices of the ``per_cell`` strongest corners (``resp`` (N,) float32) of each of the gx x gy cells of a w x h
    image, corners (N, 2) float32 [px], cell by cell and strongest first, ties in index order: numpy's
    ``order = np.lexsort((-resp, cell))`` cut to the first per_cell of each cell, the cell of a corner computed in
    float32 as numpy does, min(u gx // w, gx - 1) + gx min(v gy // h, gy - 1)."""
    n = pts.shape[0]
    fx, fy, fw, fh = np.float32(gx), np.float32(gy), np.float32(w), np.float32(h)
    # one pass in index order keeps each cell's strongest so far, strongest first: a corner enters when its cell is
    # not full or it beats the cell's weakest (strictly: on a tie the earlier index ranks first, lexsort's order),
    # behind every kept one at least as strong
    ncell = gx * gy
    top = np.empty((ncell, max(per_cell, 1)), np.int64)
    count = np.zeros(ncell, np.int64)
    for i in range(n):
        cu = min(floor_quotient(pts[i, 0] * fx, fw), gx - 1)
        cv = min(floor_quotient(pts[i, 1] * fy, fh), gy - 1)
        c = cu + gx * cv
        r = resp[i]
        k = count[c]
        if k == per_cell:
            if not (k > 0 and r > resp[top[c, k - 1]]):
                continue
            k -= 1  # the weakest leaves
        else:
            count[c] = k + 1
        while k > 0 and resp[top[c, k - 1]] < r:
            top[c, k] = top[c, k - 1]
            k -= 1
        top[c, k] = i
    keep = np.empty(n, np.int64)
    m = 0
    for c in range(ncell):
        for j in range(count[c]):
            keep[m] = top[c, j]
            m += 1
    return keep[:m]


def warm_up_corners() -> None:
    """The noise estimate's and the corner selection's compiled passes loaded now (compiled once after an install), on
    a frame's argument types, not in the first frame."""
    gray = np.zeros((3, 3), np.uint8)
    noise_sigma(gray)
    gray.flags.writeable = False  # a frame's grey image is read-only, a type of its own to numba
    noise_sigma(gray)
    _strongest_per_cell(np.zeros((0, 2), np.float32), np.zeros(0, np.float32), 1, 1, 1, 1, 1)


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
    # inside the image (a NaN or infinite position fails these comparisons too)
    u, v = p1[:, 0], p1[:, 1]
    ok = (st.ravel() == 1) & (u >= 0) & (u <= w - 1) & (v >= 0) & (v <= h - 1)
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
