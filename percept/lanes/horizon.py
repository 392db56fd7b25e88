"""Camera geometry of recorded footage from the road itself: the horizon and pitch from the lane lines.

The near parts of the lane lines are straight and parallel on the ground, so their images meet at the road's
vanishing point, whose row is the horizon (Hartley & Zisserman, *Multiple View Geometry*, 2nd ed., sec. 8.6);
with the camera rolled by ~0 and yawed by a little, pitch = atan((cy - v_vp) / fy). Segments come from a
probabilistic Hough transform on Canny edges; the point is the pair hypothesis that the most segment length
points at (an exhaustive, deterministic RANSAC), refined by weighted least squares; ``marking_vanishing_point``
refines it from the lane-marking evidence the detector labelled left and right. Intrinsics come from
``percept.sensors.chessboard`` (``percept calibrate``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from percept.sensors import PinholeCamera, StereoRig

from .evidence import marking_brightness
from .types import LaneFit, MarkingEvidence


@dataclass(frozen=True)
class VanishingPoint:
    """Vanishing point of the lane lines (u, v) [px]; segments: how many line segments (or marking points)
    agree; support_px: their total length [px] (0 for marking points); source: "segments" | "markings"."""

    u: float
    v: float
    segments: int
    support_px: float
    source: str = "segments"


def _segments(image: np.ndarray, top: int, bottom: int) -> np.ndarray:
    """Line segments (N, 4) as (u1, v1, u2, v2) [px] between rows top and bottom: probabilistic Hough on the
    Canny edges of the grey image, plus on the edges of thin bright stripes (a horizontal top-hat of the marking
    brightness, 4 % of the width wide), which keeps faint yellow-on-concrete lines."""
    w = image.shape[1]
    roi = image[top:bottom]
    gray = cv2.cvtColor(roi, cv2.COLOR_BGR2GRAY)
    mark = np.clip(marking_brightness(roi), 0, 255).astype(np.uint8)
    kernel = cv2.getStructuringElement(cv2.MORPH_RECT, (int(0.04 * w) | 1, 1))
    stripes = ((cv2.morphologyEx(mark, cv2.MORPH_TOPHAT, kernel) > 20) * 255).astype(np.uint8)
    out = []
    for edges in (cv2.Canny(cv2.GaussianBlur(gray, (5, 5), 0), 50, 150), cv2.Canny(stripes, 50, 150)):
        segs = cv2.HoughLinesP(edges, 1, np.pi / 180, 30, minLineLength=0.03 * w, maxLineGap=0.01 * w)
        if segs is not None:
            # back to full-image rows
            out.append(segs.reshape(-1, 4).astype(np.float64) + np.array([0.0, top, 0.0, top]))
    return np.vstack(out) if out else np.zeros((0, 4))


def estimate_vanishing_point(image: np.ndarray, roi_top_frac: float = 0.5, bottom_margin_frac: float = 0.07,
                             max_angle_err_rad: float = math.radians(1.5)) -> VanishingPoint | None:
    """Vanishing point of the lane lines in a BGR image, or None when no left/right pair of segments agrees.

    Segments are searched between rows roi_top_frac * H and (1 - bottom_margin_frac) * H (the hood).
    Segments between 20 and 75 deg from horizontal are lane-line candidates; left lines lean one way
    (du/dv < 0), right lines the other. A segment supports a candidate point when the direction from its
    midpoint to the point is within ``max_angle_err_rad`` of its own and the point lies above it.
    """
    h, w = image.shape[:2]
    s = _segments(image, int(roi_top_frac * h), int((1 - bottom_margin_frac) * h))
    d = s[:, 2:] - s[:, :2]
    ang = np.arctan2(np.abs(d[:, 1]), np.abs(d[:, 0]))
    keep = (ang > math.radians(20)) & (ang < math.radians(75))
    s, d = s[keep], d[keep]
    length = np.hypot(d[:, 0], d[:, 1])
    lean = np.sign(d[:, 0] * d[:, 1])
    # homogeneous line through both end points: l = p1 x p2, scaled so that l . (u, v, 1) is a distance [px]
    ones = np.ones((len(s), 1))
    lines = np.cross(np.hstack([s[:, :2], ones]), np.hstack([s[:, 2:], ones]))
    lines /= np.hypot(lines[:, 0], lines[:, 1])[:, None] + 1e-12
    mid = (s[:, :2] + s[:, 2:]) / 2
    order = np.argsort(-length)
    left, right = order[lean[order] < 0][:30], order[lean[order] > 0][:30]
    # every (left, right) pair, left-major: intersection of two lines x = l_i x l_j (H&Z sec. 2.2.1)
    pi, pj = np.repeat(left, len(right)), np.tile(right, len(left))
    x = np.cross(lines[pi], lines[pj])
    ok = np.abs(x[:, 2]) >= 1e-9
    pi, pj, x = pi[ok], pj[ok], x[ok, :2] / x[ok, 2:3]
    ok = (0 <= x[:, 0]) & (x[:, 0] < w) & (0 <= x[:, 1]) & (x[:, 1] < h)
    pi, pj, x = pi[ok], pj[ok], x[ok]
    best = None
    # pairs in chunks of at most ~2e5 pair-segment tests
    step = max(1, 200_000 // max(len(s), 1))
    for a in range(0, len(x), step):
        to_u = x[a:a + step, None, 0] - mid[None, :, 0]
        to_v = x[a:a + step, None, 1] - mid[None, :, 1]
        dist = np.hypot(to_u, to_v) + 1e-9
        # |cos| of the angle between a segment and the ray from its midpoint to x
        cos = np.abs(to_u * d[:, 0] + to_v * d[:, 1]) / (dist * length)
        inl = (cos > math.cos(max_angle_err_rad)) & (to_v < 0)
        # both leans must be seen by at least two segments each (one stray mark does not make a lane line)
        rows = np.arange(len(inl))
        good = (inl[rows, pi[a:a + step]] & inl[rows, pj[a:a + step]] & ((inl & (lean < 0)).sum(axis=1) >= 2)
                & ((inl & (lean > 0)).sum(axis=1) >= 2))
        for k in np.flatnonzero(good):
            score = float(length[inl[k]].sum())
            if best is None or score > best[0]:
                best = (score, inl[k])
    if best is None:
        return None
    score, inl = best
    # refine: min_x sum_k L_k^2 (l_k . (x, 1))^2 over the supporting segments, linear in x
    A = lines[inl, :2] * length[inl, None]
    b = -lines[inl, 2] * length[inl]
    (u, v), *_ = np.linalg.lstsq(A, b, rcond=None)
    return VanishingPoint(float(u), float(v), int(inl.sum()), score)


def marking_vanishing_point(evidence: MarkingEvidence, fit: LaneFit, span_m: float = 20.0,
                            min_points: int = 8) -> VanishingPoint | None:
    """Vanishing point from the marking evidence a fit labelled left and right: a straight image line
    u = p + q v per side through the points of the first ``span_m`` metres (weights sqrt(strength)), and their
    intersection. Over the same range both boundaries have the same heading, so on a curve too the two tangent
    lines meet on the horizon. None without ``min_points`` labelled points on each side."""
    x = evidence.points_m[:, 0]
    near = x < x.min() + span_m if len(x) else np.zeros(0, bool)
    lines, used = [], 0
    for side in (1, -1):
        m = near & (fit.side == side)
        if m.sum() < min_points:
            return None
        u, v = evidence.uv_px[m].T
        w = np.sqrt(np.clip(evidence.strength[m], 1e-6, None))
        # weighted least squares for u = p + q v
        (q, p), *_ = np.linalg.lstsq(np.column_stack([v, np.ones_like(v)]) * w[:, None], u * w, rcond=None)
        lines.append(np.array([1.0, -q, -p]))
        used += int(m.sum())
    x_h = np.cross(lines[0], lines[1])
    if abs(x_h[2]) < 1e-9:
        return None
    return VanishingPoint(float(x_h[0] / x_h[2]), float(x_h[1] / x_h[2]), used, 0.0, "markings")


def make_rig(camera: PinholeCamera, horizon_row_px: float, mount_height_m: float) -> StereoRig:
    """Monocular rig: the camera (the rig's left) level with the frame's origin (mount_x_m = 0) and half the nominal
    baseline left of it (``LaneResult.offset_m`` reports the offset at the camera), pitched so that the ground's
    horizon falls on ``horizon_row_px``: pitch = atan((cy - v_h) / fy) [rad]."""
    pitch = math.atan((camera.cy - horizon_row_px) / camera.fy)
    pitch = float(np.clip(pitch, -0.45, 0.45))
    return StereoRig(camera=camera, baseline_m=0.54, mount_height_m=mount_height_m, pitch_rad=pitch, mount_x_m=0.0)
