"""Self-calibration of a dash camera from the road it films: the lowest road row (above the hood), the horizon (pitch)
from the lane lines' vanishing point, and the camera height from a lane-width prior.

Recorded footage comes without extrinsics. The hood, when the camera sees one, ends the road (``hood.py``); the
horizon comes from the Hough segments' vanishing point, refined from the marking evidence the detector labels
(``horizon.py``; Hartley & Zisserman sec. 8.6). Every ground distance seen by one camera scales with its height
above the road (for a level camera a road point at row v lies at x = h fy / (v - v_h), y = -(u - cx) x / fx), so a
fit made at a nominal height measures the lane width up to the factor h / h_nominal; the lanes' known width (US
freeways 3.6-3.7 m) turns the median measured width into the height: h = h_nominal W_prior / median(W_measured),
measured twice (the fit's own width prior pulls the first measurement towards 3.7 m). Over a folder or the head of a
video the medians are taken over all frames, so that each frame's width is then a measurement, not the prior.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from percept.sensors import PinholeCamera, StereoRig

from .detector import LaneDetector
from .hood import common_hood_row
from .horizon import VanishingPoint, estimate_vanishing_point, make_rig, marking_vanishing_point

NOMINAL_HEIGHT_M = 1.2
"""The camera height assumed before (or without) a measurement [m]."""
HEIGHT_RANGE_M = (0.5, 5.0)
"""The heights a measurement is clipped to [m]."""
MIN_SIDE_INLIERS = 10
"""Inliers a fit needs on each side for its width to measure the height."""


@dataclass(frozen=True)
class FootageGeometry:
    """A camera's geometry from its frames: rig (intrinsics, pitch, height); vanishing_point (None: the assumed
    horizon); bottom_row_px: the lowest road row searched [px]; hood_row_px: the hood's top edge (None: no hood
    seen); height_source: "given", "lane-width prior" or "assumed" (no lane to measure: NOMINAL_HEIGHT_M)."""

    rig: StereoRig
    vanishing_point: VanishingPoint | None
    bottom_row_px: float
    hood_row_px: float | None
    height_source: str


def ground_range_at_row(rig: StereoRig, row_px: float) -> float:
    """Ground distance ahead [m] seen at image row ``row_px`` (below the horizon):
    x = h / tan(pitch + atan((v - cy) / fy))."""
    cam = rig.camera
    a = rig.pitch_rad + np.arctan((row_px - cam.cy) / cam.fy)
    return float(rig.mount_height_m / np.tan(a)) if a > 1e-4 else float("inf")


def make_detector(rig: StereoRig, cfg, bottom_row_px: float) -> LaneDetector:
    """LaneDetector for a recorded camera (``cfg``: RealLaneConfig): the near range starts at ``bottom_row_px``."""
    x_near = max(ground_range_at_row(rig, bottom_row_px) + 0.3, 2.0)
    x_far = max(cfg.x_far_m, x_near + 10.0)
    ev_cfg = replace(cfg.lane.evidence, x_near_m=x_near, x_far_m=x_far, max_row_px=bottom_row_px)
    return LaneDetector(rig, replace(cfg.lane, evidence=ev_cfg))


def median_vp(vps: list[VanishingPoint | None]) -> VanishingPoint | None:
    """The per-coordinate median of the vanishing points found (None entries left out), or None without one."""
    vps = [v for v in vps if v is not None]
    if not vps:
        return None
    return VanishingPoint(float(np.median([p.u for p in vps])), float(np.median([p.v for p in vps])),
                          int(np.median([p.segments for p in vps])), float(np.median([p.support_px for p in vps])),
                          vps[0].source)


def bottom_row(images: list[np.ndarray], cfg) -> tuple[float, float | None]:
    """(lowest road row [px], hood row or None): a fixed margin when ``cfg.bottom_margin_frac`` is set, else 3 px
    above the hood the frames show, else the last row."""
    h = images[0].shape[0]
    if cfg.bottom_margin_frac is not None:
        return (1 - cfg.bottom_margin_frac) * (h - 1), None
    hood = common_hood_row(images)
    return (h - 1.0 if hood is None else hood - 3.0), hood


def _fits(images: list[np.ndarray], det: LaneDetector) -> list:
    """(evidence, fit) of each image that gives a fit, each fitted afresh (no tracking)."""
    out = []
    for im in images:
        det.reset()
        _, dbg = det.process(im)
        if dbg.fit is not None:
            out.append((dbg.evidence, dbg.fit))
    return out


def _height_from_widths(fits: list, height_m: float, lane_width_m: float) -> float | None:
    """h W_prior / median(W) over the fits that saw both boundaries, or None without one."""
    widths = [f.estimate.width_m for _, f in fits
              if f.inliers_left >= MIN_SIDE_INLIERS and f.inliers_right >= MIN_SIDE_INLIERS]
    if not widths:
        return None
    return float(np.clip(height_m * lane_width_m / np.median(widths), *HEIGHT_RANGE_M))


def footage_geometry(images: list[np.ndarray], camera: PinholeCamera, cfg,
                     height_m: float | None = None) -> FootageGeometry:
    """The geometry of ``images`` (prepared, one size, one camera; ``cfg``: RealLaneConfig). The height is
    ``height_m``, else ``cfg.mount_height_m``, else measured from the lane-width prior over the images."""
    bottom, hood = bottom_row(images, cfg)
    h = images[0].shape[0]
    margin = 1.0 - (bottom + 1.0) / h
    vp = median_vp([estimate_vanishing_point(im, cfg.roi_top_frac, margin) for im in images])
    row = vp.v if vp is not None else cfg.horizon_frac * (h - 1)
    given = height_m if height_m is not None else cfg.mount_height_m
    height = NOMINAL_HEIGHT_M if given is None else given
    rig = make_rig(camera, row, height)
    fits = _fits(images, make_detector(rig, cfg, bottom))
    refined = median_vp([marking_vanishing_point(ev, fit) for ev, fit in fits])
    if refined is not None and abs(refined.v - row) < 0.08 * h:
        rig, vp = make_rig(camera, refined.v, height), refined
        if given is None:
            fits = _fits(images, make_detector(rig, cfg, bottom))
    source = "given"
    if given is None:
        source = "assumed"
        for again in (True, False):
            measured = _height_from_widths(fits, rig.mount_height_m, cfg.lane_width_m)
            if measured is None:
                break
            rig, source = replace(rig, mount_height_m=measured), "lane-width prior"
            if again:
                fits = _fits(images, make_detector(rig, cfg, bottom))
    return FootageGeometry(rig, vp, bottom, hood, source)
