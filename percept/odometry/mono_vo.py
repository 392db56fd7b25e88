"""Monocular visual odometry with metric scale from the known camera height over the road.

Per frame: KLT tracks (forward-backward checked, Kalal et al. 2010) from the previous frame, the essential matrix
by RANSAC (Nister 2004, "An efficient solution to the five-point relative pose problem", PAMI) and its
decomposition with the cheirality check (Hartley & Zisserman, *Multiple View Geometry*, 2nd ed., sec. 9.6), which
give the rotation R and the direction of the translation t (|t| = 1).

The translation's length comes from the road ahead. Road points X on the plane m^T X = 1 (m = n / h: normal n,
distance h in the unit-translation scale) move by the plane-induced homography H = K (R + t m^T) K^-1 (H&Z
sec. 13.1). The road region (a trapezoid on the image: the flat road within a few metres of the camera's axis) of
the previous image is aligned with the current one by ECC (Evangelidis & Psarakis 2008, OpenCV's
findTransformECC), started from the previous frame's plane, or from a sweep of h with a level normal when there is
none; the plane m is then read from H given R and t (linear least squares), and scale = camera_height_m / h
(as in e.g. Song & Chandraker 2014, "Robust scale estimation in real-time monocular SFM for autonomous driving").
The scale in use is the median of the recent estimates; when the road cannot be aligned it is the last good one.

The road is aligned directly, not fitted through triangulated corners: asphalt has few corners, a corner fit takes
the pavement beside the road, and KLT's translational model is biased by the road's perspective change.

The first frame has no motion to measure: it returns ``VOStep.failed("first frame")`` (identity motion), so a
trajectory built from the steps starts at the first camera. Dark or featureless frames, too few inliers, near-zero
motion and a first road alignment that fails also return a failed step (never an exception, never a NaN).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import cv2
import numpy as np

from .features import check_intrinsics
from .road_plane import RoadRegion, plane_from_homography, plane_homography
from .types import VOStep


@dataclass(frozen=True)
class MonoVOConfig:
    """Settings of ``MonoVO``: corners, KLT, the essential matrix, the road alignment and the scale's history
    (pixels at the input resolution)."""

    max_features: int = 1500  # corners detected (cv2.goodFeaturesToTrack)
    min_tracked: int = 600  # fewer tracked points and new corners are added (a keyframe)
    quality: float = 0.01  # goodFeaturesToTrack's quality level (share of the strongest corner's response)
    min_distance_px: float = 8.0  # least distance between two corners [px]
    klt_window_px: int = 21  # pyramidal Lucas-Kanade's window side [px]
    klt_levels: int = 3  # pyramidal Lucas-Kanade's pyramid levels
    fb_max_px: float = 1.0  # largest forward-backward tracking error kept [px]
    ransac_px: float = 1.0  # epipolar distance of an essential-matrix inlier [px]
    min_inliers: int = 30  # fewer inliers and the step fails
    min_flow_px: float = 0.5  # a median track motion below this is no motion (a failed step) [px]
    road_range_m: float = 20.0  # the road region is the level road nearer than this [m]
    road_half_width_m: float = 2.0  # ... and within this of the camera's axis [m]
    max_tilt_rad: float = 0.2  # largest angle between the road's normal and the camera's down axis [rad]
    min_road_ncc: float = 0.8  # least correlation of an accepted road alignment
    ecc_iterations: int = 50  # iterations of the ECC road alignment
    sweep_steps: int = 40  # steps the first alignment's sweep tries
    sweep_step_m: tuple[float, float] = (0.1, 5.0)  # the sweep's least and largest motion per frame [m]
    scale_window: int = 5  # scale estimates in the median
    max_scale_jump: float = 1.5  # an estimate more than this factor from the median is refused
    min_intensity_std: float = 2.0  # frames whose grey-level std is below this fail (dark or featureless)

    def __post_init__(self) -> None:
        for name in ("max_features", "min_tracked", "klt_levels", "min_inliers", "scale_window", "sweep_steps",
                     "ecc_iterations"):
            v = getattr(self, name)
            if int(v) != v or v < 1:
                raise ValueError(f"MonoVOConfig.{name} must be a whole number >= 1, got {v!r}")
        for name in ("quality", "min_distance_px", "fb_max_px", "ransac_px", "min_flow_px", "road_range_m",
                     "road_half_width_m", "max_tilt_rad", "min_road_ncc", "min_intensity_std"):
            v = getattr(self, name)
            if not np.isfinite(v) or v <= 0:
                raise ValueError(f"MonoVOConfig.{name} must be a finite number > 0, got {v!r}")
        if self.klt_window_px < 5 or self.klt_window_px % 2 == 0:
            raise ValueError(f"MonoVOConfig.klt_window_px must be odd and >= 5, got {self.klt_window_px}")
        if not self.max_scale_jump > 1:
            raise ValueError(f"MonoVOConfig.max_scale_jump must be > 1, got {self.max_scale_jump}")
        lo, hi = self.sweep_step_m
        if not 0 < lo < hi < np.inf:
            raise ValueError(f"MonoVOConfig.sweep_step_m must be (low, high) with 0 < low < high, got {lo, hi}")


class MonoVO:
    """Monocular VO: ``process(gray)`` per frame -> ``VOStep`` (motion from the previous frame, metres).

    K: (3, 3) intrinsics of the (undistorted) images [px]; camera_height_m: height of the camera's centre above
    the road [m] (KITTI: 1.65). Deterministic: the same frames give the same steps.
    """

    def __init__(self, K: np.ndarray, camera_height_m: float, config: MonoVOConfig = MonoVOConfig()):
        K = check_intrinsics(K)
        if not np.isfinite(camera_height_m) or camera_height_m <= 0:
            raise ValueError(f"camera_height_m must be a finite number > 0, got {camera_height_m}")
        self.K, self.height_m, self.cfg = K, float(camera_height_m), config
        self._road: RoadRegion | None = None
        self.reset()

    def reset(self) -> None:
        """Forget the previous frame, the tracks, the road plane and the scale history."""
        self._prev: np.ndarray | None = None
        self._pts = np.zeros((0, 2), np.float32)
        self._scales: deque[float] = deque(maxlen=self.cfg.scale_window)
        self._plane: np.ndarray | None = None  # last road plane m = n / h in the unit-translation scale
        self._frames = 0

    @property
    def scale_m(self) -> float | None:
        """The scale in use: metres per unit of the essential matrix's translation (None before the first)."""
        return float(np.median(self._scales)) if self._scales else None

    def _detect(self, gray: np.ndarray, pts: np.ndarray) -> np.ndarray:
        """``pts`` (N, 2) topped up with new corners at least min_distance_px away from them."""
        c = self.cfg
        keep = np.full(gray.shape, 255, np.uint8)
        for u, v in pts:
            cv2.circle(keep, (int(u), int(v)), int(c.min_distance_px), 0, -1)
        new = cv2.goodFeaturesToTrack(gray, c.max_features, c.quality, c.min_distance_px, mask=keep)
        return pts if new is None else np.concatenate([pts, new.reshape(-1, 2)]).astype(np.float32)

    def _track(self, prev: np.ndarray, cur: np.ndarray, pts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(points in prev, their match in cur), kept when both directions agree within fb_max_px."""
        if not len(pts):
            return pts, pts
        lk = dict(winSize=(self.cfg.klt_window_px,) * 2, maxLevel=self.cfg.klt_levels,
                  criteria=(cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, 30, 0.01))
        p1, st1, _ = cv2.calcOpticalFlowPyrLK(prev, cur, pts.reshape(-1, 1, 2), None, **lk)
        back, st2, _ = cv2.calcOpticalFlowPyrLK(cur, prev, p1, None, **lk)
        h, w = cur.shape
        p1 = p1.reshape(-1, 2)
        # forward-backward error |p0 - back(fwd(p0))|
        fb = np.linalg.norm(back.reshape(-1, 2) - pts, axis=1)
        ok = ((st1.ravel() == 1) & (st2.ravel() == 1) & (fb < self.cfg.fb_max_px) & (p1[:, 0] >= 0)
              & (p1[:, 1] >= 0) & (p1[:, 0] <= w - 1) & (p1[:, 1] <= h - 1))
        return pts[ok], p1[ok]

    def process(self, gray: np.ndarray) -> VOStep:
        """The motion of the camera from the previous frame to ``gray`` ((H, W) uint8) as a ``VOStep``."""
        gray = np.asarray(gray)
        if gray.ndim != 2 or gray.dtype != np.uint8 or min(gray.shape) < 16:
            return VOStep.failed(f"expected a (H, W) uint8 grey image of at least 16x16 px, got {gray.dtype} "
                                 f"{gray.shape}")
        if float(gray.std()) < self.cfg.min_intensity_std:
            self._prev, self._pts = None, np.zeros((0, 2), np.float32)
            return VOStep.failed("dark or featureless frame")
        prev, self._prev = self._prev, gray
        if prev is None or prev.shape != gray.shape:
            self._pts = self._detect(gray, np.zeros((0, 2), np.float32))
            why = "first frame" if self._frames == 0 else "no usable previous frame: tracking starts again"
            self._frames += 1
            return VOStep.failed(why, len(self._pts), keyframe=True)
        self._frames += 1
        keyframe = len(self._pts) < self.cfg.min_tracked
        if keyframe:
            self._pts = self._detect(prev, self._pts)
        try:
            p0, p1 = self._track(prev, gray, self._pts)
            self._pts = p1
            step = self._motion(prev, gray, p0, p1)
        except cv2.error as e:  # a degenerate configuration inside OpenCV: this step only
            self._pts, p1 = np.zeros((0, 2), np.float32), []
            step = VOStep.failed(f"OpenCV could not solve this frame ({str(e).strip().splitlines()[-1][:80]})")
        return VOStep(step.T_prev_cur, step.covariance, step.ok, len(p1), step.inliers, step.quality, keyframe,
                      step.reason)

    def _motion(self, prev: np.ndarray, cur: np.ndarray, p0: np.ndarray, p1: np.ndarray) -> VOStep:
        c, n = self.cfg, len(p0)
        if n < c.min_inliers:
            return VOStep.failed(f"only {n} tracked features (at least {c.min_inliers} needed)", n)
        if float(np.median(np.linalg.norm(p1 - p0, axis=1))) < c.min_flow_px:
            return VOStep.failed(f"no motion (median feature motion below {c.min_flow_px} px)", n)
        E, mask = cv2.findEssentialMat(p0, p1, self.K, method=cv2.RANSAC, prob=0.999, threshold=c.ransac_px)
        if E is None or E.shape[1:] != (3,) or len(E) < 3:
            return VOStep.failed("no essential matrix", n)
        E = E[:3]  # of several solutions, the first (the one with most inliers)
        good, R, t, _ = cv2.recoverPose(E, p0, p1, self.K, mask=mask.copy())
        if good < c.min_inliers or not (np.all(np.isfinite(R)) and np.all(np.isfinite(t))):
            return VOStep.failed(f"only {good} inliers (at least {c.min_inliers} needed)", n)
        measured = self._measure_scale(prev, cur, R, t)
        scale = self.scale_m
        if scale is None:
            return VOStep.failed("no road plane for the scale yet", n)
        T = np.eye(4)
        # cv2.recoverPose: x_cur = R x_prev + t  ->  T_prev_cur = [R^T | -R^T t s], s the scale [m]
        T[:3, :3] = R.T
        T[:3, 3] = -R.T @ t.reshape(3) * scale
        return VOStep(T, self._covariance(good, scale, measured), True, n, int(good), good / n)

    def _measure_scale(self, prev: np.ndarray, cur: np.ndarray, R: np.ndarray, t: np.ndarray) -> bool:
        """Align the road, add its scale to the history; whether it was accepted."""
        if self._road is None or self._road.mask.shape != cur.shape:
            self._road = RoadRegion(self.K, self.height_m, cur.shape, self.cfg)
        if not self._road.ok:
            return False
        m = self._align_road(prev, cur, R, t)
        if m is None or not np.isfinite(h := 1.0 / max(np.linalg.norm(m), 1e-12)):
            self._plane = None
            return False
        # scale = H / h: the camera's height in metres over its height in the unit-translation frame
        s, med = self.height_m / h, self.scale_m
        if med is not None and not 1 / self.cfg.max_scale_jump < s / med < self.cfg.max_scale_jump:
            self._plane = None
            return False
        self._plane = m
        self._scales.append(s)
        return True

    def _align_road(self, prev, cur, R, t) -> np.ndarray | None:
        """The road plane m (3,) from ECC alignment of the road region; None when it fails or is implausible."""
        road, c = self._road, self.cfg
        tpl = road.template(prev)
        m0 = self._plane if self._plane is not None else self._sweep(tpl, cur, R, t)
        C = road.to_crop(plane_homography(self.K, R, t, m0)).astype(np.float32)
        crit = (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, c.ecc_iterations, 1e-4)
        try:
            ncc, C = cv2.findTransformECCWithMask(tpl, cur, road.crop_mask, np.full_like(cur, 255), C,
                                                  cv2.MOTION_HOMOGRAPHY, crit, 5)
        except cv2.error:  # no convergence, or the warped region left the image
            return None
        m = plane_from_homography(self.K, R, t, C.astype(np.float64) @ np.linalg.inv(road.T_tpl))
        if m is None or ncc < c.min_road_ncc:
            return None
        # the normal n = m / |m| within max_tilt of the down axis (0, 1, 0): n_y >= cos(max_tilt)
        return m if m[1] / np.linalg.norm(m) >= np.cos(c.max_tilt_rad) else None

    def _sweep(self, tpl: np.ndarray, cur: np.ndarray, R, t) -> np.ndarray:
        """A first road plane: the level plane (normal (0, 1, 0)) whose homography best correlates the road."""
        road, lo, hi = self._road, *self.cfg.sweep_step_m
        a = cv2.GaussianBlur(tpl, (5, 5), 0).astype(np.float32)
        b = cv2.GaussianBlur(cur, (5, 5), 0).astype(np.float32)
        best, best_m = -np.inf, np.array([0.0, self.height_m / lo, 0.0])
        for step_m in np.geomspace(lo, hi, self.cfg.sweep_steps):
            m = np.array([0.0, step_m / self.height_m, 0.0])  # h = H / step in the unit-translation scale
            C = road.to_crop(plane_homography(self.K, R, t, m))
            w = cv2.warpPerspective(b, C, tpl.shape[::-1], flags=cv2.WARP_INVERSE_MAP | cv2.INTER_LINEAR,
                                    borderValue=-1.0)
            ok = (road.crop_mask > 0) & (w >= 0)
            if ok.sum() < 100:
                continue
            x, y = a[ok] - a[ok].mean(), w[ok] - w[ok].mean()
            # ZNCC = sum(x y) / sqrt(sum x^2 sum y^2)
            ncc = float(x @ y) / max(float(np.sqrt((x @ x) * (y @ y))), 1e-9)
            if ncc > best:
                best, best_m = ncc, m
        return best_m

    @staticmethod
    def _covariance(inliers: int, scale_m: float, measured: bool) -> np.ndarray:
        """Diagonal (6, 6) covariance of (rotation vector [rad], translation [m]): 1 mrad and 3 % of the step
        (+1 cm) at 200 inliers, growing as 1/sqrt(inliers); the translation's doubled when this frame's road
        gave no scale."""
        k = np.sqrt(200.0 / max(inliers, 1))
        sig_r = 1e-3 * k
        sig_t = (0.01 + 0.03 * scale_m) * k * (1.0 if measured else 2.0)
        return np.diag([sig_r**2] * 3 + [sig_t**2] * 3)
