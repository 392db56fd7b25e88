"""Road surfaces and lane paint as ground-plane polygons near the vehicle, projected to pixels.

The road's samples are indexed once in chunks with bounding circles, so a frame only transforms the
chunks within reach. Far lane paint is filtered like a texture: lines thinner than a pixel are widened
to one pixel with their contrast scaled down by the same factor, and from 40 m to 90 m the dashes
stretch over their period while fading to the period's mean (dash/period) — the far field shows the
average paint instead of sub-pixel dashes that alias and shimmer as the car moves.

The per-sample and per-piece selection is compiled (numba, ``_surface_samples`` and ``_marking_pieces``) with the
arithmetic of the vectorised numpy formulas, in their order (tests/sims/test_paint_reference.py holds it to them bit
for bit).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from numba.extending import register_jitable

from percept.compiled import kernel
from percept.sensors import Pose2D, StereoRig, rotate_to_vehicle

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

register_jitable(rotate_to_vehicle)  # the kernels below convert world points to the vehicle frame with it


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
    lv, rv, strip, first = _surface_samples(index.left, index.right, index.strip, index.lo, index.hi, index.centre,
                                            index.radius, pose.x_m, pose.y_m, math.cos(pose.yaw_rad),
                                            math.sin(pose.yaw_rad), near_x_m, SURFACE_FAR_M)
    starts = np.flatnonzero(first)
    groups: dict[int, list[np.ndarray]] = {}
    for a, b in zip(starts, np.r_[starts[1:], len(first)]):
        if b - a >= 2:
            groups.setdefault(int(strip[a]), []).append(np.concatenate([lv[a:b], rv[a:b][::-1]]))
    return [groups[k] for k in sorted(groups)]


@kernel()
def _surface_samples(left, right, strip_of, lo, hi, centre, radius, px, py, c, s, near, far):  # pragma: no cover
    """The road's samples that outline its visible surface, vehicle frame: left and right edge points (M, 2) [m],
    their strip and whether each starts a run (a polygon). A sample is visible when a chunk within reach holds it
    and both its edge points are past ``near`` and within ``far``; runs are contiguous visible samples of one
    strip, thinned by distance (every sample up to 60 m, every 4th up to 150 m, every 16th beyond, plus each run's
    ends). The vehicle pose is (px, py) [m] with c, s the cosine and sine of its yaw. Empty when fewer than two
    samples are visible."""
    n = len(left)
    mark = np.zeros(n + 1, np.int64)
    for k in range(len(lo)):
        x, y = rotate_to_vehicle(centre[k, 0] - px, centre[k, 1] - py, c, s)
        r = radius[k]
        if x > near - r and x < far + r and abs(y) < far + r:
            mark[lo[k]] += 1
            mark[hi[k] + 1] -= 1
    gi = np.empty(n, np.int64)
    pts = np.empty((n, 4))
    m, run = 0, 0
    for i in range(n):
        run += mark[i]
        if run <= 0:
            continue
        lx, ly = rotate_to_vehicle(left[i, 0] - px, left[i, 1] - py, c, s)
        rx, ry = rotate_to_vehicle(right[i, 0] - px, right[i, 1] - py, c, s)
        if lx > near and rx > near and lx < far and abs(ly) < far:
            gi[m] = i
            pts[m, 0], pts[m, 1], pts[m, 2], pts[m, 3] = lx, ly, rx, ry
            m += 1
    if m < 2:
        m = 0
    lv, rv = np.empty((m, 2)), np.empty((m, 2))
    strip, first = np.empty(m, np.int64), np.empty(m, np.bool_)
    kept = 0
    for j in range(m):
        g, st = gi[j], strip_of[gi[j]]
        # a run starts after a gap in the samples or at a new strip, and ends before one
        starts = j == 0 or gi[j] - gi[j - 1] > 1 or st != strip_of[gi[j - 1]]
        ends = j == m - 1 or gi[j + 1] - g > 1 or strip_of[gi[j + 1]] != st
        x = pts[j, 0]
        step = 1 if x < 60.0 else 4 if x < 150.0 else 16
        if g % step == 0 or starts or ends:
            lv[kept, 0], lv[kept, 1], rv[kept, 0], rv[kept, 1] = pts[j, 0], pts[j, 1], pts[j, 2], pts[j, 3]
            strip[kept], first[kept] = st, starts
            kept += 1
    return lv[:kept], rv[:kept], strip[:kept], first[:kept]


def _marking_quads(index: RoadIndex, pose: Pose2D, rig: StereoRig, palette) -> list[tuple[np.ndarray, tuple]]:
    """Lane paint as (quads (Q, 4, 2) vehicle frame [m], BGR colour) groups, filtered by distance."""
    q = index.quads
    if not len(q):
        return []
    qv, color, level = _marking_pieces(q, index.quad_centre, index.dashed, index.quad_color, pose.x_m, pose.y_m,
                                       math.cos(pose.yaw_rad), math.sin(pose.yaw_rad), rig.mount_x_m + NEAR_M,
                                       MARKING_FAR_M, rig.mount_x_m, rig.camera.fx)
    if not len(qv):
        return []
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


@kernel()
def _marking_pieces(quads, centres, dashed, colors, px, py, c, s, near, far, mount_x, fx):  # pragma: no cover
    """The paint pieces wholly between ``near`` and ``far`` ahead, in the vehicle frame (pose (px, py), c and s the
    cosine and sine of its yaw), filtered for distance: (M, 4, 2) corners [m], their colour ids and alpha levels
    (1..ALPHA_STEPS)."""
    sel = np.empty(len(quads), np.int64)
    m = 0
    for i in range(len(quads)):
        # the centre first, then every corner
        x, y = rotate_to_vehicle(centres[i, 0] - px, centres[i, 1] - py, c, s)
        if near < x < far and abs(y) < far:
            sel[m] = i
            m += 1
    qv = np.empty((m, 4, 2))
    keep = np.empty(m, np.int64)
    n = 0
    for j in range(m):
        inside = True
        for k in range(4):
            qv[n, k, 0], qv[n, k, 1] = rotate_to_vehicle(quads[sel[j], k, 0] - px, quads[sel[j], k, 1] - py, c, s)
            inside = inside and near < qv[n, k, 0] < far
        if inside:
            keep[n] = sel[j]
            n += 1
    qv = qv[:n]
    level = np.empty(n, np.int64)
    for j in range(n):
        # distance along the ground and camera depth of the piece's centre (the corners summed in order, as numpy's
        # mean over them)
        cx = (((qv[j, 0, 0] + qv[j, 1, 0]) + qv[j, 2, 0]) + qv[j, 3, 0]) / 4
        cy = (((qv[j, 0, 1] + qv[j, 1, 1]) + qv[j, 2, 1]) + qv[j, 3, 1]) / 4
        dist = math.hypot(cx, cy)
        depth = max(cx - mount_x, NEAR_M)
        # dashes stretch over the period from FADE_M[0] to FADE_M[1]: length L' = L + r (period - L), alpha L / L'
        r = min(max((dist - FADE_M[0]) / (FADE_M[1] - FADE_M[0]), 0.0), 1.0) if dashed[keep[j]] else 0.0
        ext = 1.0 + r * (DASH_GAP_M / DASH_LENGTH_M)
        for a in range(2):
            qv[j, 1, a] = qv[j, 0, a] + (qv[j, 1, a] - qv[j, 0, a]) * ext
            qv[j, 2, a] = qv[j, 3, a] + (qv[j, 2, a] - qv[j, 3, a]) * ext
        # lines narrower than MIN_WIDTH_PX are widened by k = MIN_WIDTH_PX / width_px about their centre line
        width_px = fx * MARKING_WIDTH_M / depth
        k = max(1.0, MIN_WIDTH_PX / width_px)
        for i0, i1 in ((0, 3), (1, 2)):
            for a in range(2):
                mid = (qv[j, i0, a] + qv[j, i1, a]) / 2
                h = (qv[j, i0, a] - qv[j, i1, a]) / 2 * k
                qv[j, i0, a], qv[j, i1, a] = mid + h, mid - h
        # coverage-preserving contrast: alpha = (L / L') / k, quantised to ALPHA_STEPS levels (rounded half to even)
        level[j] = int(min(max(np.rint(ALPHA_STEPS / (ext * k)), 1.0), float(ALPHA_STEPS)))
    colors_out = np.empty(n, colors.dtype)
    for j in range(n):
        colors_out[j] = colors[keep[j]]
    return qv, colors_out, level

