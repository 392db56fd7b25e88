"""The pieces every visual odometry here shares: corners spread over the image, KLT tracking, pose covariance.

References: Rosten & Drummond 2006, "Machine learning for high-speed corner detection" (FAST); Bouguet 2000,
"Pyramidal implementation of the Lucas Kanade feature tracker"; Hartley & Zisserman, sec. 5.2 (covariance
of an estimate from the Jacobian of its cost).
"""

from __future__ import annotations

import cv2
import numpy as np

from percept.compiled import floor_divide, kernel

# below this mean intensity (or standard deviation) a frame has nothing to track: dark or featureless
MIN_CONTRAST_GREY = 2.0
# FAST's threshold is at least this many times the image's noise sigma (a corner must stand out of the noise)
NOISE_GAIN = 4.0


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


@kernel()
def _noise_median_ranks(gray):  # pragma: no cover - compiled
    """The values of order (n - 1) // 2 and n // 2 of |r| over every other interior pixel (rows and columns 1, 3, ...
    up to the last but one), r the response to Immerkaer's kernel, the difference of two Laplacians (blind to planes
    and ramps), [[1, -2, 1], [-2, 4, -2], [1, -2, 1]] = [1, -2, 1]^T [1, -2, 1]: whole numbers within +-16 * 255 (what
    ``cv2.sepFilter2D`` gave in int16), counted in a histogram."""
    h, w = gray.shape
    counts = np.zeros(16 * 255 + 1, np.int64)
    n = 0
    for y in range(1, h - 1, 2):
        for x in range(1, w - 1, 2):
            r = np.int64(0)
            for dy in range(3):
                ty = 1 if dy != 1 else -2
                row = (np.int64(gray[y + dy - 1, x - 1]) - 2 * np.int64(gray[y + dy - 1, x])
                       + np.int64(gray[y + dy - 1, x + 1]))
                r += ty * row
            counts[abs(r)] += 1
            n += 1
    lo_rank, hi_rank = (n - 1) // 2, n // 2
    lo = hi = -1
    seen = 0
    for v in range(counts.size):
        seen += counts[v]
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
    resp = np.float32([k.response for k in kps])
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
    cell = np.empty(n, np.int64)
    for i in range(n):
        cu = min(floor_divide(pts[i, 0] * fx, fw), np.float32(gx - 1))
        cv = min(floor_divide(pts[i, 1] * fy, fh), np.float32(gy - 1))
        cell[i] = np.int64(cu + fx * cv)
    # the corners of each cell in index order (a counting sort), then each cell's strongest by repeated selection:
    # the largest response left, the lowest index among equal ones (lexsort's order)
    ncell = gx * gy
    starts = np.zeros(ncell + 1, np.int64)
    for i in range(n):
        starts[cell[i] + 1] += 1
    for c in range(ncell):
        starts[c + 1] += starts[c]
    members, filled = np.empty(n, np.int64), starts[:-1].copy()
    for i in range(n):
        members[filled[cell[i]]] = i
        filled[cell[i]] += 1
    taken = np.zeros(n, np.bool_)
    keep = np.empty(n, np.int64)
    m = 0
    for c in range(ncell):
        for _ in range(min(per_cell, starts[c + 1] - starts[c])):
            best = -1
            for k in range(starts[c], starts[c + 1]):
                i = members[k]
                if not taken[i] and (best < 0 or resp[i] > resp[best]):
                    best = i
            taken[best] = True
            keep[m] = best
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
