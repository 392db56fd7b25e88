"""Road surfaces and lane paint as ground-plane polygons near the vehicle, projected to pixels.

The road's samples are indexed once in chunks with bounding circles, so a frame only transforms the
chunks within reach. Far lane paint is filtered like a texture: lines thinner than a pixel are widened
to one pixel with their contrast scaled down by the same factor, and from 40 m to 90 m the dashes
stretch over their period while fading to the period's mean (dash/period) — the far field shows the
average paint instead of sub-pixel dashes that alias and shimmer as the car moves.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from percept.sensors import Pose2D, StereoRig

from ..road_geometry import DASH_GAP_M, DASH_LENGTH_M, MARKING_WIDTH_M, YELLOW, RoadGeometry
from .raster import NEAR_M

SURFACE_FAR_M = 400.0
"""Road surfaces are drawn up to this distance [m]."""
MARKING_FAR_M = 220.0
"""Lane paint is drawn up to this distance [m]."""
CHUNK = 32
FADE_M = (40.0, 90.0)
MIN_WIDTH_PX = 1.0
ALPHA_STEPS = 8


class RoadIndex:
    """The road's strips concatenated (left, right: (N, 2) world [m], strip: (N,)) with chunks of CHUNK samples
    (lo, hi inclusive sample indices, centre (C, 2), radius (C,)); marking quads with their centres,
    colour and whether they are dashes."""

    def __init__(self, road: RoadGeometry):
        lefts, rights, sid, lo, hi = [], [], [], [], []
        n0 = 0
        for k, s in enumerate(road.strips):
            n = len(s.left)
            lefts.append(s.left)
            rights.append(s.right)
            sid.append(np.full(n, k))
            starts = np.arange(0, max(n - 1, 1), CHUNK)
            lo.append(n0 + starts)
            hi.append(n0 + np.minimum(starts + CHUNK, n - 1))
            n0 += n
        self.left = np.concatenate(lefts) if lefts else np.zeros((0, 2))
        self.right = np.concatenate(rights) if rights else np.zeros((0, 2))
        self.strip = np.concatenate(sid) if sid else np.zeros(0, int)
        self.lo = np.concatenate(lo) if lo else np.zeros(0, int)
        self.hi = np.concatenate(hi) if hi else np.zeros(0, int)
        cen, rad = [], []
        for a, b in zip(self.lo, self.hi):
            p = np.concatenate([self.left[a:b + 1], self.right[a:b + 1]])
            c = (p.min(axis=0) + p.max(axis=0)) / 2
            cen.append(c)
            rad.append(np.linalg.norm(p - c, axis=1).max())
        self.centre = np.asarray(cen).reshape(-1, 2)
        self.radius = np.asarray(rad)
        q, color = road.marking_quads, road.marking_color
        if len(q):
            # a line shared by two lanes is declared by both: keep one copy of each piece (same corners to
            # 1 cm, in any order; the grid is offset from round coordinates), since OpenCV fills overlapping
            # polygons of one call even-odd
            corners = np.round(q * 100 + 0.3137).astype(np.int64).view(np.dtype((np.void, 16))).reshape(len(q), 4)
            key = np.sort(corners, axis=1).view(np.dtype((np.void, 64))).ravel()
            _, first = np.unique(key, return_index=True)
            keep = np.sort(first)
            q, color = q[keep], color[keep]
        self.quads = q
        self.quad_centre = q.mean(axis=1) if len(q) else np.zeros((0, 2))
        self.quad_color = color
        length = np.linalg.norm(q[:, 1] - q[:, 0], axis=1) if len(q) else np.zeros(0)
        self.dashed = np.abs(length - DASH_LENGTH_M) < 1e-3


def to_pixels(Hg: np.ndarray, xy_v: np.ndarray) -> np.ndarray:
    """Vehicle-frame ground points (..., 2) -> pixel coordinates (..., 2), fixed point with 4 fractional bits."""
    # (u, v, 1) ~ Hg (x, y, 1)
    p = xy_v @ Hg[:, :2].T + Hg[:, 2]
    uv = p[..., :2] / p[..., 2:3]
    return np.clip(np.round(uv * 16), -2**24, 2**24).astype(np.int32)


@dataclass(frozen=True)
class GroundPaint:
    """Road surfaces and paint near the vehicle in its frame, shared by both cameras.

    points: (N, 2) vehicle-frame ground points [m] of every polygon (surfaces, then paint quads);
    surfaces: per strip, the (start, end) point ranges of its polygons; marks: (start, end, BGR colour)
    point ranges of paint quads (4 points each) filled in one call."""

    points: np.ndarray
    surfaces: list[list[tuple[int, int]]]
    marks: list[tuple[int, int, tuple]]

    def project(self, Hg: np.ndarray) -> tuple[list[list[np.ndarray]], list[tuple[np.ndarray, tuple]]]:
        """Pixel polygons (fixed point, 4 bits) for the camera whose ground homography is ``Hg``."""
        px = to_pixels(Hg, self.points)
        surf = [[px[a:b] for a, b in runs] for runs in self.surfaces]
        marks = [(px[a:b].reshape(-1, 4, 2), col) for a, b, col in self.marks]
        return surf, marks


def ground_paint(index: RoadIndex, pose: Pose2D, rig: StereoRig, palette) -> GroundPaint:
    """Select and filter the road's surfaces and paint for the vehicle at ``pose``."""
    near = rig.mount_x_m + NEAR_M
    parts: list[np.ndarray] = []
    n = 0
    surfaces = []
    for polys in _surface_polygons(index, pose, near):
        runs = []
        for p in polys:
            parts.append(p)
            runs.append((n, n + len(p)))
            n += len(p)
        surfaces.append(runs)
    marks = []
    for quads, col in _marking_quads(index, pose, rig, palette):
        parts.append(quads.reshape(-1, 2))
        marks.append((n, n + 4 * len(quads), col))
        n += 4 * len(quads)
    pts = np.concatenate(parts) if parts else np.zeros((0, 2))
    return GroundPaint(pts, surfaces, marks)


def _surface_polygons(index: RoadIndex, pose: Pose2D, near_x_m: float) -> list[list[np.ndarray]]:
    """Paved-surface polygons, vehicle frame [m], one list per strip."""
    if not len(index.lo):
        return []
    cv = pose.to_vehicle_xy(index.centre)
    r = index.radius
    sel = np.flatnonzero((cv[:, 0] > near_x_m - r) & (cv[:, 0] < SURFACE_FAR_M + r)
                         & (np.abs(cv[:, 1]) < SURFACE_FAR_M + r))
    if not len(sel):
        return []
    # samples covered by the selected chunks: +1 at each chunk start, -1 after its end, running sum > 0
    mark = np.zeros(len(index.left) + 1, np.int32)
    np.add.at(mark, index.lo[sel], 1)
    np.add.at(mark, index.hi[sel] + 1, -1)
    idx = np.flatnonzero(np.cumsum(mark)[:-1] > 0)
    lv = pose.to_vehicle_xy(index.left[idx])
    rv = pose.to_vehicle_xy(index.right[idx])
    ok = (lv[:, 0] > near_x_m) & (rv[:, 0] > near_x_m) & (lv[:, 0] < SURFACE_FAR_M) & (np.abs(lv[:, 1]) < SURFACE_FAR_M)
    keep = np.flatnonzero(ok)
    if len(keep) < 2:
        return []
    gi = idx[keep]
    strip = index.strip[gi]
    # contiguous runs of visible samples of one strip, one polygon each
    brk = (np.diff(gi) > 1) | (np.diff(strip) != 0)
    first, last = np.r_[True, brk], np.r_[brk, True]
    # level of detail: every sample up to 60 m, every 4th up to 150 m, every 16th beyond (plus run ends)
    x = lv[keep, 0]
    step = np.where(x < 60.0, 1, np.where(x < 150.0, 4, 16))
    dec = np.flatnonzero((gi % step == 0) | first | last)
    keep, gi, strip, first = keep[dec], gi[dec], strip[dec], first[dec]
    lv, rv = lv[keep], rv[keep]
    starts = np.flatnonzero(first)
    groups: dict[int, list[np.ndarray]] = {}
    for a, b in zip(starts, np.r_[starts[1:], len(keep)]):
        if b - a >= 2:
            groups.setdefault(int(strip[a]), []).append(np.concatenate([lv[a:b], rv[a:b][::-1]]))
    return [groups[k] for k in sorted(groups)]


def _marking_quads(index: RoadIndex, pose: Pose2D, rig: StereoRig, palette) -> list[tuple[np.ndarray, tuple]]:
    """Lane paint as (quads (Q, 4, 2) vehicle frame [m], BGR colour) groups, filtered by distance."""
    q = index.quads
    if not len(q):
        return []
    near = rig.mount_x_m + NEAR_M
    c = pose.to_vehicle_xy(index.quad_centre)
    close = np.flatnonzero((c[:, 0] > near) & (c[:, 0] < MARKING_FAR_M) & (np.abs(c[:, 1]) < MARKING_FAR_M))
    qv = pose.to_vehicle_xy(q[close])
    ok = (qv[..., 0].min(axis=1) > near) & (qv[..., 0].max(axis=1) < MARKING_FAR_M)
    qv, sel = qv[ok], close[ok]
    if not len(qv):
        return []
    dashed, color = index.dashed[sel], index.quad_color[sel]
    # distance along the ground and camera depth of each piece's centre
    cen = qv.mean(axis=1)
    dist = np.hypot(cen[:, 0], cen[:, 1])
    depth = np.maximum(cen[:, 0] - rig.mount_x_m, NEAR_M)
    # dashes stretch over the period from FADE_M[0] to FADE_M[1]: length L' = L + r (period - L), alpha L / L'
    r = np.where(dashed, np.clip((dist - FADE_M[0]) / (FADE_M[1] - FADE_M[0]), 0, 1), 0.0)
    ext = 1.0 + r * (DASH_GAP_M / DASH_LENGTH_M)
    qv[:, 1] = qv[:, 0] + (qv[:, 1] - qv[:, 0]) * ext[:, None]
    qv[:, 2] = qv[:, 3] + (qv[:, 2] - qv[:, 3]) * ext[:, None]
    # lines narrower than MIN_WIDTH_PX are widened by k = MIN_WIDTH_PX / width_px about their centre line
    width_px = rig.camera.fx * MARKING_WIDTH_M / depth
    k = np.maximum(1.0, MIN_WIDTH_PX / width_px)
    for i, j in ((0, 3), (1, 2)):
        m = (qv[:, i] + qv[:, j]) / 2
        h = (qv[:, i] - qv[:, j]) / 2 * k[:, None]
        qv[:, i], qv[:, j] = m + h, m - h
    # coverage-preserving contrast: alpha = (L / L') / k, quantised to ALPHA_STEPS levels
    level = np.clip(np.round(ALPHA_STEPS / (ext * k)), 1, ALPHA_STEPS).astype(int)
    asphalt = np.asarray(palette.asphalt, np.float64)
    key = color.astype(int) * (ALPHA_STEPS + 1) + level
    order = np.argsort(-key, kind="stable")
    key, qv = key[order], qv[order]
    out = []
    starts = np.flatnonzero(np.r_[True, np.diff(key) != 0])
    for a, b in zip(starts, np.r_[starts[1:], len(key)]):
        col_id, lv = divmod(int(key[a]), ALPHA_STEPS + 1)
        paint = np.asarray(palette.yellow_paint if col_id == YELLOW else palette.white_paint, np.float64)
        # colour = asphalt + alpha (paint - asphalt)
        bgr = asphalt + (lv / ALPHA_STEPS) * (paint - asphalt)
        out.append((qv[a:b], tuple(float(math.floor(x + 0.5)) for x in bgr)))
    return out
