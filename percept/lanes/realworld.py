"""The lane module on recorded dash-camera footage: a self-calibrated geometry, then the same LaneDetector.

Recorded footage comes without extrinsics: ``footage_geometry`` finds the lowest road row (above the hood, when
one is seen), the horizon (pitch) from the lane lines' vanishing point, and, without a given height, the camera
height from a lane-width prior. Intrinsics come from a calibration file (Zhang 2000) or an assumed horizontal
field of view. A still gets a fresh detector and its own horizon (the height measured over a folder of one
camera's stills by ``FootageLanes.calibrate``); a video gets one geometry (from its first frames) and Kalman
tracking at an assumed speed. Each boundary is reported from the bottom row to the far end of its own evidence.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field, replace

import numpy as np

from percept.sensors import CameraCalibration, PinholeCamera, StereoRig

from .detector import LaneConfig, LaneDebug, LaneDetector
from .footage_geometry import FootageGeometry, footage_geometry, ground_range_at_row, make_detector
from .horizon import VanishingPoint
from .evidence import Brightness, EvidenceConfig
from .fit import FitConfig
from .types import LaneEstimate
from .vehicles import VehicleConfig


def _real_lane_config() -> LaneConfig:
    """The detector's settings for recorded footage."""
    # lower stripe thresholds than in the simulator: white dashes on pale concrete are faint. Grid rows every 4 image
    # rows near the camera (a 0.25 m step there skips 20 rows of a 720-row frame, leaving a near dash 2-3 points and
    # the near boundary to the far evidence). Freeway geometry (radius >= ~500 m, spirals >= ~100 m at
    # 100 km/h) changes curvature by at most ~2e-5 per metre, and a single frame seen to 40 m cannot tell a cubic
    # from a quadratic: the curvature-rate prior is that tight. A vehicle over a marking masks it (``vehicles.py``).
    return LaneConfig(evidence=EvidenceConfig(min_contrast=6.0, rel_contrast=0.2, brightness=Brightness.MAX_RG_YELLOW,
                                              row_step_px=4.0, vehicles=VehicleConfig()),
                      fit=FitConfig(curvature_rate_sigma_1pm2=3e-5, straight_seeds=True))


@dataclass(frozen=True)
class RealLaneConfig:
    """Settings of the lane detector on recorded footage: the assumed camera, the rows used and the tracking."""

    hfov_rad: float = math.radians(60.0)  # assumed horizontal field of view without calibration [rad]
    mount_height_m: float | None = None  # camera height above the road [m]; None: estimated from the lane width
    # the width of the lanes filmed (US freeways 3.6-3.7 m) [m], which sets the height when it is not given
    lane_width_m: float = 3.65
    horizon_frac: float = 0.58  # horizon row as a fraction of the image height when no vanishing point is found
    roi_top_frac: float = 0.5  # top of the rows searched for lane segments, as a fraction of the height
    # rows left out at the bottom, as a fraction of the height; None: down to the car's hood when one is seen
    # (``hood.py``), else to the last row
    bottom_margin_frac: float | None = None
    x_far_m: float = 60.0  # farthest ground range used [m]
    speed_mps: float = 0.0  # assumed speed for tracking through a video (no odometry) [m/s]
    horizon_frames: int = 15  # video frames whose median horizon (and height) is used
    # the detector's configuration (x_near_m is set from the lowest usable row)
    lane: LaneConfig = field(default_factory=_real_lane_config)

    def __post_init__(self) -> None:
        if not 0.05 < self.hfov_rad < math.pi - 0.05:
            raise ValueError(f"field of view {math.degrees(self.hfov_rad):.1f} deg is outside (3, 177) deg")
        if self.mount_height_m is not None and not 0.2 <= self.mount_height_m <= 10.0:
            raise ValueError(f"mount height {self.mount_height_m} m is outside [0.2, 10] m")
        if not 2.0 <= self.lane_width_m <= 6.0:
            raise ValueError(f"lane width {self.lane_width_m} m is outside [2, 6] m")
        margin = 0.0 if self.bottom_margin_frac is None else self.bottom_margin_frac
        if not 0.0 <= margin < 0.4 or not 0.0 <= self.roi_top_frac < 1 - margin:
            raise ValueError(f"rows {self.roi_top_frac}..{1 - margin} of the height are not a band")
        if not math.isfinite(self.speed_mps) or self.speed_mps < 0:
            raise ValueError(f"assumed speed {self.speed_mps} m/s must be finite and >= 0")
        if self.horizon_frames < 1:
            raise ValueError(f"horizon_frames must be at least 1, got {self.horizon_frames}")


def boundary_points_px(rig: StereoRig, est: LaneEstimate, x_near_m: float, x_far_m: float,
                       n: int = 40) -> dict[str, np.ndarray]:
    """Both boundaries projected into the image: {"left"|"right": (m <= n, 2) (u, v) [px]} of
    ``est.boundary_points_m`` (the points in front of the camera)."""
    out = {}
    for name, pts in est.boundary_points_m(x_near_m, x_far_m, n).items():
        uv, z = rig.project_vehicle_points(pts)
        out[name] = uv[z > 0.1]
    return out


def boundary_u_at_rows(rig: StereoRig, est: LaneEstimate, side: int, rows_px: np.ndarray,
                       x_range_m: tuple[float, float]) -> np.ndarray:
    """Column [px] of a boundary (``side`` +1 left, -1 right) at each image row of ``rows_px``, NaN where the row
    sees the road outside ``x_range_m`` (near, far) [m] or lies above the horizon: the row's ground range x, the
    boundary's y there, projected."""
    rows = np.asarray(rows_px, dtype=float)
    x = np.array([ground_range_at_row(rig, v) for v in rows])
    inside = np.isfinite(x) & (x >= x_range_m[0] - 1e-6) & (x <= x_range_m[1] + 1e-6)
    u = np.full(len(rows), np.nan)
    if inside.any():
        xs = x[inside]
        uv, z = rig.project_vehicle_points(np.column_stack([xs, est.boundary_y(xs, side), np.zeros_like(xs)]))
        u[inside] = np.where(z > 0.1, uv[:, 0], np.nan)
    return u


def boundaries_over_ranges(rig: StereoRig, est: LaneEstimate, ranges: dict[str, tuple[float, float]],
                           n: int = 40) -> dict[str, np.ndarray]:
    """Each boundary in the image over its own ground range: {"left"|"right": (m <= n, 2) (u, v) [px]}, ``n``
    points evenly spaced on the ground from the near end (the bottom row) to the far end."""
    return {name: boundary_points_px(rig, est, *ranges[name], n=n)[name] for name in ("left", "right")}


@dataclass(frozen=True)
class LaneResult:
    """One image's outcome: the estimate (invalid when no lane was found), the detector's debug data, the
    camera's geometry, both boundaries in the image {"left"|"right": (N, 2) (u, v) [px]} from the bottom row to
    the far end of each one's evidence, and the ground ranges they span, x_ranges_m {"left"|"right": (near, far)}
    [m]."""

    estimate: LaneEstimate
    debug: LaneDebug
    geometry: FootageGeometry
    boundaries_px: dict[str, np.ndarray]
    x_ranges_m: dict[str, tuple[float, float]]

    @property
    def rig(self) -> StereoRig:
        return self.geometry.rig

    @property
    def vanishing_point(self) -> VanishingPoint | None:
        return self.geometry.vanishing_point

    @property
    def offset_m(self) -> float:
        """The camera's lateral offset from the lane centre [m] (+ left), which footage reports as the car's (a dash
        camera sits on the car's centreline). The fit's frame (``horizon.make_rig``) has its origin half the rig's
        nominal baseline right of the camera, so its offset is the origin's: offset_cam = offset + y_cam (the lane
        centre at the car is y_c = -offset)."""
        return self.estimate.offset_m + float(self.rig.camera_position()[1])

    @property
    def both_found(self) -> bool:
        f = self.debug.fit
        return bool(self.estimate.valid and f is not None and f.inliers_left >= 5 and f.inliers_right >= 5)

    def u_at_rows(self, rows_px: np.ndarray) -> dict[str, np.ndarray]:
        """Each boundary's column [px] at ``rows_px``, NaN outside its drawn range (or without a lane)."""
        if not self.estimate.valid:
            return {k: np.full(len(rows_px), np.nan) for k in ("left", "right")}
        return {name: boundary_u_at_rows(self.rig, self.estimate, side, rows_px, self.x_ranges_m[name])
                for name, side in (("left", 1), ("right", -1))}

    def to_dict(self) -> dict:
        """The result as JSON-ready values (None where there is no lane)."""
        e, g = self.estimate, self.geometry
        vp = g.vanishing_point
        num = (lambda v: float(v) if e.valid else None)
        return {"lanes": [{"side": k, "points_px": np.round(v, 1).tolist()} for k, v in self.boundaries_px.items()],
                "offset_m": num(self.offset_m), "heading_rad": num(e.heading_rad),
                "curvature_1pm": num(e.curvature_1pm), "width_m": num(e.width_m),
                "confidence": float(e.confidence) if e.valid else 0.0,
                "ambiguity": None if self.debug.fit is None else round(self.debug.fit.ambiguity, 3),
                "both_boundaries": self.both_found, "pitch_rad": self.rig.pitch_rad,
                "horizon_row_px": self.rig.horizon_row,
                "vanishing_point_px": None if vp is None else [round(vp.u, 1), round(vp.v, 1)],
                "horizon_source": "assumed" if vp is None else vp.source,
                "mount_height_m": round(self.rig.mount_height_m, 3), "mount_height_source": g.height_source,
                "hood_row_px": g.hood_row_px, "bottom_row_px": g.bottom_row_px,
                "vehicles_px": [[b.u0_px, b.u1_px, b.bottom_px] for b in ev.vehicles] if (ev := self.debug.evidence)
                else []}


def _drawn_ranges(det: LaneDetector, dbg: LaneDebug) -> dict[str, tuple[float, float]]:
    """Ground range [m] to draw each boundary over: from the lowest road row (the fit carried the few tenths of a
    metre below the evidence grid's first row) to its farthest inlier marking (the full range for a side without
    one)."""
    ev = det.cfg.evidence
    near = ev.x_near_m if ev.max_row_px is None else min(ground_range_at_row(det.rig, ev.max_row_px), ev.x_near_m)
    fit = dbg.fit
    out = {}
    for name, side in (("left", 1), ("right", -1)):
        mine = None if fit is None or dbg.evidence is None else fit.side == side
        far = float(dbg.evidence.points_m[mine, 0].max()) if mine is not None and mine.any() else ev.x_far_m
        out[name] = (near, float(np.clip(far, ev.x_near_m + 5.0, ev.x_far_m)))
    return out


class FootageLanes:
    """The lane detector on recorded footage of one camera: stills (a fresh detector and horizon per image, no
    tracking) or a video (one geometry for the whole video, Kalman tracking at the assumed speed). Without a
    given height, ``calibrate`` measures it over a set of stills (one camera); otherwise each still measures its
    own."""

    def __init__(self, cfg: RealLaneConfig = RealLaneConfig(), calibration: CameraCalibration | None = None):
        self.cfg, self.calibration = cfg, calibration
        self._undistort = calibration.undistorter() if calibration is not None else None
        self.height_m: float | None = cfg.mount_height_m
        self.height_source = "given" if cfg.mount_height_m is not None else None

    def prepare(self, image: np.ndarray) -> np.ndarray:
        """Undistort with the calibration (maps computed once; ValueError on a size mismatch), or pass through."""
        if image is None or image.ndim != 3 or image.shape[2] != 3:
            raise ValueError("expected a BGR colour image")
        return image if self._undistort is None else self._undistort(image)

    def for_prepared(self) -> "FootageLanes":
        """The same camera (and height) for images ``prepare`` has already undistorted: a runner that takes them as
        they are (a tool that draws on the undistorted image before fitting, for instance)."""
        out = copy.copy(self)
        out._undistort = None
        return out

    def camera(self, width: int, height: int) -> PinholeCamera:
        """The calibrated camera, or one of ``cfg.hfov_rad`` for images ``width`` x ``height`` [px]."""
        if self.calibration is not None:
            return self.calibration.camera
        return PinholeCamera.from_hfov(width, height, self.cfg.hfov_rad)

    def geometry(self, images: list[np.ndarray]) -> FootageGeometry:
        """The geometry of prepared ``images`` of one size (``footage_geometry``), at the known height if any."""
        h, w = images[0].shape[:2]
        g = footage_geometry(images, self.camera(w, h), self.cfg, self.height_m)
        return g if self.height_source is None else replace(g, height_source=self.height_source)

    def calibrate(self, images: list[np.ndarray]) -> float | None:
        """Measure the camera height over stills of one camera (each with its own horizon): the median of the
        heights the lane-width prior gives on each; later stills use it. None (and nothing changes) when no still
        shows both boundaries or the height is given."""
        if self.height_m is not None:
            return None
        heights = []
        for im in images:
            g = self.geometry([self.prepare(im)])
            if g.height_source == "lane-width prior":
                heights.append(g.rig.mount_height_m)
        if not heights:
            return None
        self.height_m, self.height_source = float(np.median(heights)), f"lane-width prior ({len(heights)} images)"
        return self.height_m

    def _result(self, det: LaneDetector, est: LaneEstimate, dbg: LaneDebug, geometry: FootageGeometry) -> LaneResult:
        ranges = _drawn_ranges(det, dbg)
        pts = boundaries_over_ranges(det.rig, est, ranges) if est.valid else {}
        return LaneResult(est, dbg, geometry, pts, ranges)

    def still(self, image: np.ndarray) -> LaneResult:
        """One image on its own: its own horizon (and height, unless known), a fresh detector, the frame's fit."""
        img = self.prepare(image)
        g = self.geometry([img])
        det = make_detector(g.rig, self.cfg, g.bottom_row_px)
        _, dbg = det.process(img)
        est = dbg.fit.estimate if dbg.fit is not None else LaneEstimate(0.0, 0.0, 0.0, 0.0, 0.0, valid=False)
        return self._result(det, est, dbg, g)

    def video(self, frames, fps: float):
        """Yield (prepared frame, LaneResult) per frame of the iterable ``frames`` (BGR); the geometry comes from the
        first ``cfg.horizon_frames`` frames; tracking with dt = 1 / fps [s] at the assumed speed."""
        it = iter(frames)
        head = []
        for f in it:
            head.append(self.prepare(f))
            if len(head) >= self.cfg.horizon_frames:
                break
        if not head:
            return
        g = self.geometry(head)
        det = make_detector(g.rig, self.cfg, g.bottom_row_px)
        dt = 1.0 / fps if fps and fps > 0 else 1.0 / 25

        def all_frames():
            yield from head
            for f in it:
                yield self.prepare(f)

        for img in all_frames():
            est, dbg = det.process(img, self.cfg.speed_mps, 0.0, dt)
            yield img, self._result(det, est, dbg, g)
