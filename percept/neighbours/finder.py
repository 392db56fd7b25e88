"""One rig's vehicle finder: its band stereo, the ground grid's groups and each face's subpixel range."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from percept.sensors import LaneEstimate, Side, StereoRig

from .clusters import VEHICLE_LENGTH_M, VEHICLE_WIDTH_M, ClusterConfig, Detection, Face, find_vehicles, lane_coordinates
from .points import BandStereo, PointsConfig, StandingPoints
from .quantiles import median, quantiles
from .refine import refine_face


EDGE_PX = 48
"""A face narrower than ``FULL_FACE_M`` whose points come this close to the image's side edge is cut off by it
(block matching leaves the last columns unmatched) [px]."""
CUT_OFF_SIGMA_X_M = 2.5
"""The along-lane 1-sigma of a cut-off face: the nearest point seen is on the car's side, at the image's edge [m]."""
OCCLUSION_PX = 2
"""A face's edge within this of a nearer car, as the rig sees it, is hidden by it [px]."""
HIDDEN_SHARE = 0.5
"""A face narrower than a whole one is taken as hidden on the side where a nearer car covers at least this share of
what the rest of a whole car's face would span, and more of it than on the other side [-]."""
FULL_FACE_M = 1.6
"""A face at least this wide is seen whole [m]."""
NEAR_LIMIT_MARGIN_M = 1.0
"""A face read within this of the nearest camera depth matched is at the near limit: the parts of the car nearer than
that depth go unmatched and those beyond are what is read, so the car may be nearer than read, by up to a couple of
metres at night or in rain [m]."""
EDGE_SIGMA_PX = 1.5
"""1-sigma of a whole face's edges in the image [px], so the lateral place of a face at range Z is uncertain by
Z EDGE_SIGMA_PX / f (at night and in rain the lit or wet parts of a car, not its outline, bound its points: the
tracker's Huber weighting takes their larger misses)."""


class RigFinder:
    """The vehicles one rig sees within [x_lo, x_hi] along the ego lane (faces), per frame."""

    def __init__(self, rig: StereoRig, x_lo: float, x_hi: float, points: PointsConfig = PointsConfig(),
                 clusters: ClusterConfig = ClusterConfig()):
        self.rig, self.x_lo, self.x_hi, self.clusters = rig, x_lo, x_hi, clusters
        self.stereo = BandStereo(rig, points)
        self.fb = rig.camera.fx * rig.baseline_m
        self.cam = np.asarray(rig.camera_position(Side.LEFT), dtype=np.float32)
        self.cam_x = float(self.cam[0])
        self.near_m = points.near_m
        self._pair: tuple[np.ndarray, np.ndarray] | None = None
        self._lane: LaneEstimate | None = None

    def find(self, left_gray: np.ndarray, right_gray: np.ndarray, lane: LaneEstimate | None
             ) -> tuple[list[Detection], StandingPoints]:
        """The detections of one grey pair, and the standing points they came from."""
        pts = self.stereo.points(left_gray, right_gray)
        self._pair, self._lane = (left_gray, right_gray), lane
        found = find_vehicles(pts, lane, self.x_lo, self.x_hi, self.face_range, self.clusters,
                              self.rig.mount_height_m)
        found = [self.cut_off(d) for d in found]
        shadows = [self.shadow(d) for d in found]
        return [self.at_depth(self.occluded(d, shadows)) for d in found], pts

    def shadow(self, det: Detection) -> tuple[float, float, float]:
        """(range of its face along the lane [m], least and greatest bearing [-]) of the corners of a detected car's
        footprint, a whole car's width at least: its face and its length away from the rig, as the rig sees them,
        widened by ``OCCLUSION_PX``."""
        w = max(det.width_m, VEHICLE_WIDTH_M)
        away = math.copysign(VEHICLE_LENGTH_M, det.face_x_m - self.cam_x)
        b = [self._bearing(det.face_x_m + a, det.lat_m + s * w / 2) for s in (-1, 1) for a in (0.0, away)]
        tol = OCCLUSION_PX / self.rig.camera.fx
        return abs(det.face_x_m), min(b) - tol, max(b) + tol

    def occluded(self, det: Detection, shadows: list[tuple[float, float, float]]) -> Detection:
        """``det`` with its lateral centre put half a car's width beyond its free edge when its face is narrower than
        a whole one and a nearer car (``shadows``: each detection's ``shadow``) hides, as the rig sees it, at least
        ``HIDDEN_SHARE`` of what the rest of a whole car's face would span beyond its other edge, and more than beyond
        the free one (a car seen past another shows only the part the nearer one leaves, and a dark face's points are
        only at its edges: the middle of the part seen is off by up to half a car's width)."""
        if det.cut_off or det.width_m >= FULL_FACE_M:
            return det
        lo, hi = (self._bearing(det.face_x_m, det.lat_m + s * det.width_m / 2) for s in (-1, 1))
        # where the face would end on each side, were it a whole car's width with its other edge where it is seen
        lo_whole, hi_whole = (self._bearing(det.face_x_m, det.lat_m - s * (det.width_m / 2 - VEHICLE_WIDTH_M))
                              for s in (-1, 1))
        hidden_lo = hidden_hi = 0.0
        for near, b0, b1 in shadows:
            if near >= abs(det.face_x_m):
                continue
            # the share of what a whole car's face would span beyond each edge that the nearer car hides
            hidden_lo = max(hidden_lo, max(min(b1, lo) - max(b0, lo_whole), 0.0) / max(lo - lo_whole, 1e-9))
            hidden_hi = max(hidden_hi, max(min(b1, hi_whole) - max(b0, hi), 0.0) / max(hi_whole - hi, 1e-9))
        if max(hidden_lo, hidden_hi) < HIDDEN_SHARE or hidden_lo == hidden_hi:
            return det
        return replace(det, lat_m=self._beyond_seen_edge(det, 1.0 if hidden_hi > hidden_lo else -1.0))

    def _bearing(self, x_m: float, lat_m: float) -> float:
        """The bearing [-] at which the rig sees the point ``lat_m`` from the ego lane's centre line at ``x_m`` along
        it: (y - y_c) / |x - x_c| in the vehicle frame, y = lat + the centre line's y at x."""
        lane = self._lane if self._lane is not None and self._lane.valid else None
        y = lat_m + (float(lane.centre_y(x_m)) if lane is not None else 0.0)
        return (y - float(self.cam[1])) / max(abs(x_m - self.cam_x), 0.5)

    @staticmethod
    def _beyond_seen_edge(det: Detection, missing: float) -> float:
        """The centre of a car whose face is seen only in part, the part on side ``missing`` (+1 left, -1 right) not
        seen: centre = seen edge + missing W_v / 2 [m]."""
        seen = det.lat_m - missing * det.width_m / 2
        return seen + missing * VEHICLE_WIDTH_M / 2

    def at_depth(self, det: Detection) -> Detection:
        """``det`` with what its face's camera depth Z says: the lateral 1-sigma of its centre (its face's edges' pixel
        noise at Z and, for a face seen only in part and not cut off by the image's edge, half the width it lacks of a
        whole car's: the part seen may be either side of the car, or its middle), and ``near_limit`` when Z is within
        ``NEAR_LIMIT_MARGIN_M`` of the nearest depth matched (``PointsConfig.near_m``)."""
        # Z = |x_face - x_cam| along the lane; sigma_l = Z sigma_u / f
        z = abs(det.face_x_m - self.cam_x)
        edges = z * EDGE_SIGMA_PX / self.rig.camera.fx
        # (W_v - w) / 2 for a face of width w < W_v, in quadrature
        lacks = 0.0 if det.cut_off else max(VEHICLE_WIDTH_M - det.width_m, 0.0) / 2
        return replace(det, sigma_lat_m=float(np.hypot(edges, lacks)), near_limit=z < self.near_m + NEAR_LIMIT_MARGIN_M)

    def cut_off(self, det: Detection) -> Detection:
        """``det`` marked as cut off when it reaches the image's side edge (a car coming alongside); when its face is
        narrower than a whole one, its lateral centre put half a car's width beyond the face's edge that is seen and
        its along-lane position given little weight: the middle of a cut face would drift towards the ego lane, and
        its nearest point is on the car's side where the image ends, which lags the car."""
        width = self.rig.camera.width
        if det.cut_off:  # a side seen alone, placed already
            return det
        # the image's left edge looks to the vehicle's left for a forward rig, to its right for a rear one
        left_side = -1.0 if self.rig.looks_back else 1.0
        if det.box_px[0] <= EDGE_PX:
            missing = left_side
        elif det.box_px[2] >= width - EDGE_PX:
            missing = -left_side
        else:
            return det
        if det.width_m >= FULL_FACE_M:
            return replace(det, cut_off=True)
        return replace(det, lat_m=self._beyond_seen_edge(det, missing), sigma_x_m=CUT_OFF_SIGMA_X_M, cut_off=True)

    def face_range(self, pts: StandingPoints, idx: np.ndarray, group: np.ndarray) -> Face | None:
        """The face of points ``idx`` measured at its refined disparity: its along-lane position and 1-sigma, and the
        lateral extent of the points of its ``group`` at that disparity, each moved along its ray to the refined
        range (a point's own block-matching disparity puts a car beside a few tenths of a metre off at 50 m)."""
        d0 = float(median(pts.d[idx]))
        tol = min(1.0, 0.05 * d0)
        # every matched pixel of the face's box within 5 % (at most a pixel) of its median disparity
        box = (int(pts.u[idx].min()), int(pts.v[idx].min()), int(pts.u[idx].max()) + 1, int(pts.v[idx].max()) + 1)
        u, v = self.stereo.matcher_for(d0).pixels_near(box, d0, tol)
        refined = refine_face(*self._pair, u, v, d0)
        if refined is None:
            return None
        d, sigma_d = refined
        # a point on its ray at another depth: p = c + (p_i - c) Z / Z_i, and Z / Z_i = d_i / d
        x = self.cam_x + (pts.x[idx] - self.cam_x) * (pts.d[idx] / d)
        # sigma_Z = Z^2 sigma_d / (f b)
        z = self.fb / d
        return Face(float(median(x)), float(z * z * sigma_d / self.fb), self._lateral_extent(pts, group, d0, tol, d))

    def _lateral_extent(self, pts: StandingPoints, group: np.ndarray, d0: float, tol: float, d: float
                        ) -> tuple[float, float] | None:
        """The 5 % and 95 % lateral quantiles, from the ego lane's centre line [m], of the points of ``group`` within
        ``tol`` of disparity ``d0``, each moved along its ray to disparity ``d`` [px]; None when under 6 are."""
        at = group[np.abs(pts.d[group] - d0) <= tol]
        if len(at) < 6:
            return None
        s = (pts.d[at] / np.float32(d))[:, None]
        p = self.cam[:2] + (np.stack([pts.x[at], pts.y[at]], axis=1) - self.cam[:2]) * s
        moved = StandingPoints(pts.u[at], pts.v[at], pts.d[at], p[:, 0], p[:, 1], pts.z[at])
        _, lat, _ = lane_coordinates(moved, self._lane)
        lo, hi = quantiles(lat, [0.05, 0.95])
        return float(lo), float(hi)
