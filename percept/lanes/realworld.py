"""The lane module on recorded dash-camera footage: self-calibrated extrinsics, then the same LaneDetector.

Recorded footage comes without extrinsics. The horizon, hence the pitch, comes from the lane lines' vanishing
point (``calibration.estimate_vanishing_point``: Hough segments, Hartley & Zisserman sec. 8.6), refined once
from the marking evidence the detector labels (``calibration.marking_vanishing_point``). Intrinsics come from a
calibration file (Zhang 2000) or an assumed horizontal field of view; the mount height [m] only scales the
metric values (offset, width and 1/curvature are proportional to it). A still gets a fresh detector and its own
horizon; a video gets one rig (median horizon of its first frames) and Kalman tracking at an assumed speed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from percept.sensors import CameraCalibration, PinholeCamera, StereoRig

from .horizon import VanishingPoint, estimate_vanishing_point, make_rig, marking_vanishing_point
from .detector import LaneConfig, LaneDebug, LaneDetector
from .evidence import Brightness, EvidenceConfig
from .fit import FitConfig
from .types import LaneEstimate


def _real_lane_config() -> LaneConfig:
    # lower stripe thresholds than in the simulator: white dashes on pale concrete are faint. Freeway geometry
    # (radius >= ~500 m, spirals >= ~100 m at 100 km/h) changes curvature by at most ~2e-5 per metre, and a single
    # frame seen to 40 m cannot tell a cubic from a quadratic: the curvature-rate prior is that tight.
    return LaneConfig(evidence=EvidenceConfig(min_contrast=6.0, rel_contrast=0.2, brightness=Brightness.MAX_RG_YELLOW),
                      fit=FitConfig(curvature_rate_sigma_1pm2=3e-5))


@dataclass(frozen=True)
class RealLaneConfig:
    """hfov_rad: assumed horizontal field of view without calibration [rad]; mount_height_m: camera height above
    the road [m]; horizon_frac: horizon row as a fraction of the image height when no vanishing point is found;
    roi_top_frac, bottom_margin_frac: rows searched for lane segments, and rows left out at the bottom (a car's
    hood), as fractions of the height; x_far_m: farthest ground range used [m]; speed_mps: assumed speed for
    tracking through a video (no odometry) [m/s]; horizon_frames: video frames whose median horizon is used;
    lane: the detector's configuration (x_near_m is set from the lowest usable row)."""

    hfov_rad: float = math.radians(60.0)
    mount_height_m: float = 1.2
    horizon_frac: float = 0.58
    roi_top_frac: float = 0.5
    bottom_margin_frac: float = 0.07
    x_far_m: float = 40.0
    speed_mps: float = 0.0
    horizon_frames: int = 15
    lane: LaneConfig = field(default_factory=_real_lane_config)

    def __post_init__(self) -> None:
        if not 0.05 < self.hfov_rad < math.pi - 0.05:
            raise ValueError(f"field of view {math.degrees(self.hfov_rad):.1f} deg is outside (3, 177) deg")
        if not 0.2 <= self.mount_height_m <= 10.0:
            raise ValueError(f"mount height {self.mount_height_m} m is outside [0.2, 10] m")
        if not 0.0 <= self.bottom_margin_frac < 0.4 or not 0.0 <= self.roi_top_frac < 1 - self.bottom_margin_frac:
            raise ValueError(f"rows {self.roi_top_frac}..{1 - self.bottom_margin_frac} of the height are not a band")
        if not math.isfinite(self.speed_mps) or self.speed_mps < 0:
            raise ValueError(f"assumed speed {self.speed_mps} m/s must be finite and >= 0")
        if self.horizon_frames < 1:
            raise ValueError(f"horizon_frames must be at least 1, got {self.horizon_frames}")


def ground_range_at_row(rig: StereoRig, row_px: float) -> float:
    """Ground distance ahead [m] seen at image row ``row_px`` (below the horizon):
    x = h / tan(pitch + atan((v - cy) / fy))."""
    cam = rig.camera
    a = rig.pitch_rad + math.atan((row_px - cam.cy) / cam.fy)
    return rig.mount_height_m / math.tan(a) if a > 1e-4 else float("inf")


def make_detector(rig: StereoRig, cfg: RealLaneConfig) -> LaneDetector:
    """LaneDetector for a recorded camera: the near range starts at the lowest usable row (above the hood)."""
    bottom = (1 - cfg.bottom_margin_frac) * (rig.camera.height - 1)
    x_near = max(ground_range_at_row(rig, bottom) + 0.5, 3.0)
    x_far = max(cfg.x_far_m, x_near + 10.0)
    ev_cfg = replace(cfg.lane.evidence, x_near_m=x_near, x_far_m=x_far, max_row_px=bottom)
    return LaneDetector(rig, replace(cfg.lane, evidence=ev_cfg))


def boundary_points_px(rig: StereoRig, est: LaneEstimate, x_near_m: float, x_far_m: float,
                       n: int = 40) -> dict[str, np.ndarray]:
    """Both boundaries projected into the image: {"left"|"right": (m <= n, 2) (u, v) [px]} of
    ``est.boundary_points_m`` (the points in front of the camera)."""
    out = {}
    for name, pts in est.boundary_points_m(x_near_m, x_far_m, n).items():
        uv, z = rig.project_vehicle_points(pts)
        out[name] = uv[z > 0.1]
    return out


@dataclass(frozen=True)
class LaneResult:
    """One image's outcome: the estimate (invalid when no lane was found), the detector's debug data, the rig
    used, the vanishing point (None when the fallback horizon was used), both boundaries in the image
    {"left"|"right": (N, 2) (u, v) [px]} and the ground range they span, x_range_m (near, far) [m]."""

    estimate: LaneEstimate
    debug: LaneDebug
    rig: StereoRig
    vanishing_point: VanishingPoint | None
    boundaries_px: dict[str, np.ndarray]
    x_range_m: tuple[float, float]

    @property
    def both_found(self) -> bool:
        f = self.debug.fit
        return bool(self.estimate.valid and f is not None and f.inliers_left >= 5 and f.inliers_right >= 5)

    def to_dict(self) -> dict:
        e = self.estimate
        vp = self.vanishing_point
        num = (lambda v: float(v) if e.valid else None)
        return {"lanes": [{"side": k, "points_px": np.round(v, 1).tolist()} for k, v in self.boundaries_px.items()],
                "offset_m": num(e.offset_m), "heading_rad": num(e.heading_rad), "curvature_1pm": num(e.curvature_1pm),
                "width_m": num(e.width_m), "confidence": float(e.confidence) if e.valid else 0.0,
                "both_boundaries": self.both_found, "pitch_rad": self.rig.pitch_rad,
                "horizon_row_px": self.rig.horizon_row,
                "vanishing_point_px": None if vp is None else [round(vp.u, 1), round(vp.v, 1)],
                "horizon_source": "assumed" if vp is None else vp.source}


def _drawn_range(det: LaneDetector, dbg: LaneDebug) -> tuple[float, float]:
    """Ground range [m] to draw: from the near limit to the farthest inlier marking (the full range without a fit)."""
    ev = det.cfg.evidence
    fit = dbg.fit
    if fit is None or dbg.evidence is None or not (fit.side != 0).any():
        return ev.x_near_m, ev.x_far_m
    x_max = float(dbg.evidence.points_m[fit.side != 0, 0].max())
    return ev.x_near_m, float(np.clip(x_max, ev.x_near_m + 5.0, ev.x_far_m))


def _median_vp(vps: list[VanishingPoint | None]) -> VanishingPoint | None:
    vps = [v for v in vps if v is not None]
    if not vps:
        return None
    return VanishingPoint(float(np.median([p.u for p in vps])), float(np.median([p.v for p in vps])),
                          int(np.median([p.segments for p in vps])), float(np.median([p.support_px for p in vps])),
                          vps[0].source)


class FootageLanes:
    """The lane detector on recorded footage of one camera: stills (a fresh detector per image, no tracking)
    or a video (one rig for the whole video, Kalman tracking at the assumed speed)."""

    def __init__(self, cfg: RealLaneConfig = RealLaneConfig(), calibration: CameraCalibration | None = None):
        self.cfg, self.calibration = cfg, calibration
        self._undistort = calibration.undistorter() if calibration is not None else None

    def prepare(self, image: np.ndarray) -> np.ndarray:
        """Undistort with the calibration (maps computed once; ValueError on a size mismatch), or pass through."""
        if image is None or image.ndim != 3 or image.shape[2] != 3:
            raise ValueError("expected a BGR colour image")
        return image if self._undistort is None else self._undistort(image)

    def camera(self, width: int, height: int) -> PinholeCamera:
        if self.calibration is not None:
            return self.calibration.camera
        return PinholeCamera.from_hfov(width, height, self.cfg.hfov_rad)

    def rig_for(self, images: list[np.ndarray]) -> tuple[StereoRig, VanishingPoint | None]:
        """The rig for ``images`` (prepared, one size, one camera): the median vanishing point of the Hough
        segments (without any, the horizon is ``horizon_frac`` of the height), then the median vanishing point of
        the marking evidence a detector on that rig labels, when it lies within 8 % of the height of the first."""
        h, w = images[0].shape[:2]
        cam, cfg = self.camera(w, h), self.cfg
        vp = _median_vp([estimate_vanishing_point(im, cfg.roi_top_frac, cfg.bottom_margin_frac) for im in images])
        row = vp.v if vp is not None else cfg.horizon_frac * (h - 1)
        rig = make_rig(cam, row, cfg.mount_height_m)
        det = make_detector(rig, cfg)
        found = []
        for im in images:
            det.reset()
            _, dbg = det.process(im)
            if dbg.fit is not None:
                found.append(marking_vanishing_point(dbg.evidence, dbg.fit))
        refined = _median_vp(found)
        if refined is not None and abs(refined.v - row) < 0.08 * h:
            return make_rig(cam, refined.v, cfg.mount_height_m), refined
        return rig, vp

    def _result(self, det: LaneDetector, est: LaneEstimate, dbg: LaneDebug, vp) -> LaneResult:
        near, far = _drawn_range(det, dbg)
        pts = boundary_points_px(det.rig, est, near, far) if est.valid else {}
        return LaneResult(est, dbg, det.rig, vp, pts, (near, far))

    def still(self, image: np.ndarray) -> LaneResult:
        """One image on its own: its own vanishing point, a fresh detector, the frame's fit (no tracking)."""
        img = self.prepare(image)
        rig, vp = self.rig_for([img])
        det = make_detector(rig, self.cfg)
        _, dbg = det.process(img)
        est = dbg.fit.estimate if dbg.fit is not None else LaneEstimate(0.0, 0.0, 0.0, 0.0, 0.0, valid=False)
        return self._result(det, est, dbg, vp)

    def video(self, frames, fps: float):
        """Yield (prepared frame, LaneResult) per frame of the iterable ``frames`` (BGR); the rig comes from the
        first ``cfg.horizon_frames`` frames; tracking with dt = 1 / fps [s] at the assumed speed."""
        it = iter(frames)
        head = []
        for f in it:
            head.append(self.prepare(f))
            if len(head) >= self.cfg.horizon_frames:
                break
        if not head:
            return
        rig, vp = self.rig_for(head)
        det = make_detector(rig, self.cfg)
        dt = 1.0 / fps if fps and fps > 0 else 1.0 / 25

        def all_frames():
            yield from head
            for f in it:
                yield self.prepare(f)

        for img in all_frames():
            est, dbg = det.process(img, self.cfg.speed_mps, 0.0, dt)
            yield img, self._result(det, est, dbg, vp)

