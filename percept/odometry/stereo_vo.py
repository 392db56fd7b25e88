"""Stereo visual odometry: keyframe points with stereo depth, KLT tracking, PnP with RANSAC.

At a keyframe, corners (FAST, strongest per grid cell) in the left image get their depth from the right image
(KLT along the row of a rectified pair, Z = f b / d); in later frames they are tracked with KLT and the camera
pose relative to the keyframe comes from PnP with RANSAC (points on moving vehicles and pedestrians disagree
with the static world's motion and fall out as outliers) refined by Levenberg-Marquardt on the inliers; with a
motion prior (wheel speed and gyro) that most points agree with, Levenberg-Marquardt starts from the prior and
drops the points it cannot fit, without RANSAC. A new keyframe starts when too few inliers are left.
References: Nistér, Naroditsky & Bergen 2004, "Visual odometry" (CVPR); Geiger, Ziegler & Stiller 2011,
"StereoScan" (IV); Hartley & Zisserman, ch. 6-7 (PnP).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import cv2
import numpy as np

from percept.sensors import to_gray

from .features import check_intrinsics, detect_corners, noise_sigma, pose_covariance, track, warm_up_corners
from .point_cuts import agreeing, warm_up_cuts, within
from .types import VOStep


@dataclass(frozen=True)
class StereoVOConfig:
    """Settings of ``StereoVO``: corners, KLT windows by the keyframe's light, stereo matches, PnP and the prior's
    gate (pixels at the input resolution)."""

    max_features: int = 400  # corners per keyframe
    grid: tuple[int, int] = (10, 6)  # cells (columns, rows) the corners are spread over
    fast_threshold: int = 5  # FAST's least intensity threshold [grey levels]
    # a large window holds enough texture through rain's streaks; a motion nothing predicts needs it too
    win_px: int = 15  # KLT window side without a motion prior, and with one from a low-contrast keyframe [px]
    levels: int = 3  # KLT pyramid levels without a motion prior
    # at night the beam's light stays put in the image while the road moves through it, a brightness change KLT's
    # constancy assumption cannot explain: a smaller window holds less of it
    dark_grey: float = 70.0  # below this mean grey level a keyframe is dark (simulated night 53-56, daylight 85+)
    dark_win_px: int = 11  # KLT window side from a dark keyframe, with a motion prior or without [px]
    prior_levels: int = 1  # KLT pyramid levels with a motion prior from a dark or low-contrast keyframe
    low_contrast_grey: float = 36.0  # below this grey-level std a keyframe has low contrast (rain 25-33, day 40+)
    # small windows on one level by day with contrast: a motion prior says where to start
    lit_win_px: int = 11  # KLT window side with a motion prior from a lit keyframe with contrast [px]
    lit_prior_levels: int = 0  # KLT pyramid levels with a motion prior from a lit keyframe with contrast
    max_row_err_px: float = 0.7  # a stereo match must stay this close to its row (rectified pair) [px]
    min_disparity_px: float = 0.5  # the farthest usable point's disparity, f b / Z [px]
    min_inliers: int = 12  # fewer PnP inliers and the step fails
    keyframe_inliers: int = 60  # fewer PnP inliers and this frame starts a new keyframe
    ransac_px: float = 0.7  # PnP's reprojection threshold of an inlier [px]
    # with a motion prior, a point further than prior_gate_px + prior_gate_frac x (its image motion since the
    # keyframe) from where the prior puts it is left out of PnP: it moves (a vehicle, a person) or was tracked wrongly
    prior_gate_px: float = 3.0  # the gate's constant part [px]
    prior_gate_frac: float = 0.15  # the gate's share of the point's image motion since the keyframe

    def __post_init__(self) -> None:
        if self.max_features < 20 or self.min_inliers < 6 or self.keyframe_inliers < self.min_inliers:
            raise ValueError("need max_features >= 20, min_inliers >= 6 and keyframe_inliers >= min_inliers")
        if not (min(self.win_px, self.dark_win_px, self.lit_win_px) >= 5
                and min(self.levels, self.prior_levels, self.lit_prior_levels) >= 0 and self.ransac_px > 0
                and self.min_disparity_px > 0):
            raise ValueError("win_px, dark_win_px and lit_win_px >= 5, levels, prior_levels and lit_prior_levels >= 0, "
                             "ransac_px > 0 and min_disparity_px > 0 are required")


_LAST_ROW = np.array([0.0, 0.0, 0.0, 1.0])


def _inverse(T: np.ndarray) -> np.ndarray:
    """The inverse of the rigid (4, 4) transform ``T``."""
    R = T[:3, :3]
    out = np.empty((4, 4))
    # T^-1 = [R^T, -R^T t]
    out[:3, :3] = R.T
    out[:3, 3] = -R.T @ T[:3, 3]
    out[3] = _LAST_ROW
    return out


def _matrix(rvec: np.ndarray, tvec: np.ndarray) -> np.ndarray:
    """(4, 4) [R(rvec), t] of a rotation vector and a translation (3, 1)."""
    T = np.empty((4, 4))
    T[:3, :3] = cv2.Rodrigues(rvec)[0]
    T[:3, 3] = tvec.ravel()
    T[3] = _LAST_ROW
    return T


RANSAC_SEED = 1234


class StereoVO:
    """Frame-to-keyframe stereo odometry of a rectified pair. K: (3, 3) intrinsics of both cameras [px];
    baseline_m: distance between the optical centres [m] (the right camera is at +b along the left's x)."""

    def __init__(self, K: np.ndarray, baseline_m: float, camera_height_m: float | None = None,
                 config: StereoVOConfig = StereoVOConfig()):
        K = check_intrinsics(K)
        if not (np.isfinite(baseline_m) and baseline_m > 0):
            raise ValueError(f"baseline_m must be positive, got {baseline_m}")
        if camera_height_m is not None and not (np.isfinite(camera_height_m) and camera_height_m > 0):
            raise ValueError(f"camera_height_m must be positive, got {camera_height_m}")
        self.K, self.baseline_m, self.config = K, float(baseline_m), config
        self.camera_height_m = camera_height_m
        warm_up_corners()
        warm_up_cuts()
        self.reset()

    def reset(self) -> None:
        """Forget the keyframe: the next frame starts a new one. RANSAC's random generator is re-seeded, so that a
        run gives the same result whatever ran before it in the process."""
        cv2.setRNGSeed(RANSAC_SEED)
        self._kf_points: np.ndarray | None = None  # (N, 3) keyframe camera frame [m]
        self._pixels: np.ndarray | None = None  # (N, 2) where they are in the previous left image
        self._kf_pixels: np.ndarray | None = None  # (N, 2) where they were in the keyframe's left image
        self._movers: list[tuple] = []  # this frame's boxes of things that move
        self._noise: float | None = None  # the keyframe image's noise sigma [grey levels]
        self._win_px = self.config.win_px  # the KLT window from the keyframe on [px]
        self._prior_levels = self.config.prior_levels  # KLT's pyramid levels with a motion prior, likewise
        self._free_win_px = self.config.win_px  # the KLT window of tracking without a motion prior [px]
        self._prev: np.ndarray | None = None  # previous left image (grey)
        self._T_kf_prev = np.eye(4)  # previous camera in the keyframe's frame
        self._cov_prev = np.zeros((6, 6))

    def process(self, left: np.ndarray | None, right: np.ndarray | None, prior: np.ndarray | None = None,
                movers: list | tuple = ()) -> VOStep:
        """Motion from the previous processed frame to this one. A missing image (dropped frame) returns a failed
        step and keeps the keyframe, so tracking resumes on the next frame. ``prior``: (4, 4) the expected camera
        motion since the previous processed frame (from wheel speed and gyro, as T_prev_cur): it starts KLT where
        each point should be and keeps points that move on their own out of PnP. ``movers``: boxes (u0, v0, u1, v1)
        in the left image of things known to move (vehicles, people): no point inside one is used."""
        self._movers = [tuple(map(float, b)) for b in movers if b is not None]
        if left is None or right is None:
            return VOStep.failed("dropped frame")
        if np.shape(left)[:2] != np.shape(right)[:2]:
            raise ValueError(f"left and right images differ in size: {np.shape(left)} and {np.shape(right)}")
        gl = to_gray(left)
        if self._kf_points is None or self._prev is None or self._prev.shape != gl.shape:
            return self._start_keyframe(gl, right, "first frame")
        step = self._track(gl, None if prior is None else self._T_kf_prev @ np.asarray(prior, float))
        if step.ok and step.inliers >= self.config.keyframe_inliers:
            self._prev = gl
            return step
        # too few inliers left: this frame (whose motion is already measured when ok) becomes the keyframe
        new = self._start_keyframe(gl, right, step.reason or "keyframe")
        return replace(step, keyframe=True) if step.ok else new

    def _start_keyframe(self, gl: np.ndarray, right: np.ndarray, reason: str) -> VOStep:
        """Corners of the left image with their stereo depth become the keyframe (the right image is only read
        here)."""
        c = self.config
        self._noise = noise_sigma(gl)
        # the grey levels' mean (dark keyframes track with smaller windows) and spread (featureless ones have no
        # corners; low-contrast ones track with larger windows on a pyramid) in one pass
        mean, spread = (float(m[0, 0]) for m in cv2.meanStdDev(gl))
        if mean < c.dark_grey:
            self._win_px, self._prior_levels, self._free_win_px = c.dark_win_px, c.prior_levels, c.dark_win_px
        elif spread < c.low_contrast_grey:
            self._win_px, self._prior_levels, self._free_win_px = c.win_px, c.prior_levels, c.win_px
        else:
            self._win_px, self._prior_levels, self._free_win_px = c.lit_win_px, c.lit_prior_levels, c.win_px
        corners = detect_corners(gl, c.max_features, c.grid, c.fast_threshold, noise=self._noise, spread=spread)
        if self._movers:
            corners = corners[self._static(corners)]
        self._prev, self._T_kf_prev, self._cov_prev = gl, np.eye(4), np.zeros((6, 6))
        self._kf_points = self._pixels = self._kf_pixels = None
        if len(corners) < c.min_inliers:
            return VOStep.failed(f"{reason}: only {len(corners)} corners (dark or featureless)", keyframe=True)
        matched, ok = track(gl, to_gray(right), corners, self._win_px, c.levels, self._disparity_guess(corners))
        d = corners[:, 0] - matched[:, 0]
        ok &= (np.abs(corners[:, 1] - matched[:, 1]) <= c.max_row_err_px) & (d >= c.min_disparity_px)
        if ok.sum() < c.min_inliers:
            return VOStep.failed(f"{reason}: only {int(ok.sum())} stereo matches", keyframe=True)
        px, d = corners[ok], d[ok]
        fx, fy, cx, cy = self.K[0, 0], self.K[1, 1], self.K[0, 2], self.K[1, 2]
        # Z = f b / d; X = (u - cx) Z / fx; Y = (v - cy) Z / fy
        z = fx * self.baseline_m / d
        self._kf_points = np.column_stack([(px[:, 0] - cx) * z / fx, (px[:, 1] - cy) * z / fy, z])
        self._pixels = self._kf_pixels = px
        return VOStep.failed(reason, tracked=len(px), keyframe=True)

    def _disparity_guess(self, px: np.ndarray) -> np.ndarray | None:
        """Where a corner should be in the right image if it were on a level road seen from a level camera of
        known height (the near road's disparity is beyond KLT's pyramid reach); points above it (things
        standing up) are closer to the guess than to zero. None without a camera height."""
        if self.camera_height_m is None:
            return None
        # road at row v: Z = fy h / (v - cy), so d = fx b / Z = b (v - cy) fx / (fy h); 80 % of it
        d = 0.8 * self.baseline_m * np.maximum(px[:, 1] - self.K[1, 2], 0.0) * self.K[0, 0] / (
            self.K[1, 1] * self.camera_height_m)
        return np.column_stack([px[:, 0] - d, px[:, 1]])

    def _static(self, px: np.ndarray) -> np.ndarray:
        """(N,) bool: the pixel lies outside every box of a mover."""
        keep = np.ones(len(px), bool)
        for u0, v0, u1, v1 in self._movers:
            keep &= ~((px[:, 0] >= u0) & (px[:, 0] <= u1) & (px[:, 1] >= v0) & (px[:, 1] <= v1))
        return keep

    def _project(self, T_kf_cur: np.ndarray) -> np.ndarray:
        """Where the keyframe's points are seen from a camera at ``T_kf_cur``: (N, 2) [px]."""
        T = _inverse(T_kf_cur)
        p = self._kf_points @ T[:3, :3].T + T[:3, 3]
        z = np.maximum(p[:, 2], 1e-3)
        # u = fx X / Z + cx, v = fy Y / Z + cy
        return np.column_stack([self.K[0, 0] * p[:, 0] / z + self.K[0, 2], self.K[1, 1] * p[:, 1] / z + self.K[1, 2]])

    def _track(self, gl: np.ndarray, T_kf_pred: np.ndarray | None) -> VOStep:
        c = self.config
        expected = None if T_kf_pred is None else self._project(T_kf_pred)
        if expected is None:
            moved, ok = track(self._prev, gl, self._pixels, self._free_win_px, c.levels)
        else:
            moved, ok = track(self._prev, gl, self._pixels, self._win_px, self._prior_levels, expected)
        if self._movers:
            ok &= self._static(moved)
        self._kf_points, self._pixels, self._kf_pixels = self._kf_points[ok], moved[ok], self._kf_pixels[ok]
        n = len(self._pixels)
        if n < c.min_inliers:
            return VOStep.failed(f"only {n} points tracked", tracked=n)
        use = np.arange(n)
        if expected is not None:
            # |seen - expected| against the gate, which widens with the point's motion since the keyframe
            agree = agreeing(self._pixels, expected[ok], self._kf_pixels, c.prior_gate_px, c.prior_gate_frac)
            if len(agree) >= max(c.min_inliers, n // 3):
                use = agree
                # the prior agrees with most points: start from it instead of sampling minimal solutions
                found = self._refine_from(use, T_kf_pred)
                if found is not None:
                    return self._solved(n, *found)
        # minimal solutions by EPnP inside RANSAC (no initial guess to lead it astray), then LM on the inliers
        found, rvec, tvec, inl = cv2.solvePnPRansac(self._kf_points[use], self._pixels[use], self.K, None,
                                                    iterationsCount=100, reprojectionError=c.ransac_px,
                                                    confidence=0.999, flags=cv2.SOLVEPNP_EPNP)
        if not found or inl is None or len(inl) < c.min_inliers:
            return VOStep.failed(f"PnP found {0 if inl is None else len(inl)} inliers of {n}", tracked=n)
        idx = use[inl.ravel()]
        rvec, tvec = cv2.solvePnPRefineLM(self._kf_points[idx], self._pixels[idx], self.K, None, rvec, tvec)
        return self._solved(n, idx, rvec, tvec)

    def _refine_from(self, use: np.ndarray, T_kf_pred: np.ndarray) -> tuple | None:
        """PnP by Levenberg-Marquardt from the prior's pose on the points ``use``, cutting the points whose
        reprojection error exceeds 3 x, then 1 x, ransac_px and refining again: (inlier indices, rvec, tvec), or
        None when fewer than half the points survive (the prior was off: RANSAC decides)."""
        c = self.config
        T = _inverse(T_kf_pred)
        rvec, tvec = cv2.Rodrigues(T[:3, :3])[0], T[:3, 3].reshape(3, 1).copy()
        points, pixels = self._kf_points[use], self._pixels[use]
        idx, kept_points, kept_pixels = use, points, pixels
        for cut_px in (3.0 * c.ransac_px, c.ransac_px):
            rvec, tvec = cv2.solvePnPRefineLM(kept_points, kept_pixels, self.K, None, rvec, tvec)
            seen = cv2.projectPoints(points, rvec, tvec, self.K, None)[0].reshape(-1, 2)
            idx, kept_points, kept_pixels = within(seen, pixels, points, use, cut_px)
            if len(idx) < max(c.min_inliers, len(use) // 2):
                return None
        rvec, tvec = cv2.solvePnPRefineLM(kept_points, kept_pixels, self.K, None, rvec, tvec)
        return idx, rvec, tvec

    def _solved(self, n: int, idx: np.ndarray, rvec: np.ndarray, tvec: np.ndarray) -> VOStep:
        """The step from the pose (rvec, tvec: keyframe -> current camera) found on the inliers ``idx`` of the
        ``n`` tracked points."""
        if not all(map(math.isfinite, rvec.ravel().tolist() + tvec.ravel().tolist())):
            return VOStep.failed("PnP diverged", tracked=n)
        # keep the inliers only: outliers (moving objects, bad tracks) would pull later frames too
        self._kf_points, self._pixels = self._kf_points[idx], self._pixels[idx]
        self._kf_pixels = self._kf_pixels[idx]
        cov = pose_covariance(self._kf_points, self._pixels, self.K, rvec, tvec)
        # T_kf_cur = (T_cur_kf)^-1, where PnP gives p_cur = R p_kf + t
        T_kf_cur = _inverse(_matrix(rvec, tvec))
        # T_prev_cur = T_kf_prev^-1 T_kf_cur; both poses carry their own error (their correlation is ignored)
        T_prev_cur = _inverse(self._T_kf_prev) @ T_kf_cur
        step_cov = cov + self._cov_prev
        self._T_kf_prev, self._cov_prev = T_kf_cur, cov
        return VOStep(T_prev_cur, step_cov, True, n, len(idx), len(idx) / n, T_key_cur=T_kf_cur, key_covariance=cov,
                      noise_grey=self._noise)
