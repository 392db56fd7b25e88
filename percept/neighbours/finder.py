"""One rig's vehicle finder: its band stereo, the ground grid's groups and each face's subpixel range."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from percept.sensors import LaneEstimate, Side, StereoRig

from .clusters import VEHICLE_WIDTH_M, ClusterConfig, Detection, find_vehicles
from .points import BandStereo, PointsConfig, StandingPoints
from .refine import refine_face


EDGE_PX = 48
"""A face narrower than ``FULL_FACE_M`` whose points come this close to the image's side edge is cut off by it
(block matching leaves the last columns unmatched) [px]."""
CUT_OFF_SIGMA_X_M = 2.5
"""The along-lane 1-sigma of a cut-off face: the nearest point seen is on the car's side, at the image's edge [m]."""
FULL_FACE_M = 1.6
"""A face at least this wide is seen whole [m]."""
EDGE_SIGMA_PX = 3.0
"""1-sigma of a face's edges in the image [px]: at night and in rain the lit or wet parts of a car, not its outline,
bound its points, so the lateral place of a face at range Z is uncertain by Z EDGE_SIGMA_PX / f."""


class RigFinder:
    """The vehicles one rig sees within [x_lo, x_hi] along the ego lane (faces), per frame."""

    def __init__(self, rig: StereoRig, x_lo: float, x_hi: float, points: PointsConfig = PointsConfig(),
                 clusters: ClusterConfig = ClusterConfig()):
        self.rig, self.x_lo, self.x_hi, self.clusters = rig, x_lo, x_hi, clusters
        self.stereo = BandStereo(rig, points)
        self.fb = rig.camera.fx * rig.baseline_m
        self.cam_x = float(rig.camera_position(Side.LEFT)[0])
        self._pair: tuple[np.ndarray, np.ndarray] | None = None

    def find(self, left_gray: np.ndarray, right_gray: np.ndarray, lane: LaneEstimate | None
             ) -> tuple[list[Detection], StandingPoints]:
        """The detections of one grey pair, and the standing points they came from."""
        pts = self.stereo.points(left_gray, right_gray)
        self._pair = (left_gray, right_gray)
        found = find_vehicles(pts, lane, self.x_lo, self.x_hi, self.face_range, self.clusters,
                              self.rig.mount_height_m)
        return [self.lateral_sigma(self.cut_off(d)) for d in found], pts

    def lateral_sigma(self, det: Detection) -> Detection:
        """``det`` with the lateral 1-sigma of its face's edges at its range."""
        # sigma_l = Z sigma_u / f, Z the face's range from the camera along the lane
        z = abs(det.face_x_m - self.cam_x)
        return replace(det, sigma_lat_m=z * EDGE_SIGMA_PX / self.rig.camera.fx)

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
        # the seen edge is the one away from the missing side: centre = seen edge + missing W_v / 2
        seen = det.lat_m - missing * det.width_m / 2
        return replace(det, lat_m=seen + missing * VEHICLE_WIDTH_M / 2, sigma_x_m=CUT_OFF_SIGMA_X_M, cut_off=True)

    def face_range(self, pts: StandingPoints, idx: np.ndarray) -> tuple[float, float] | None:
        """The face's along-lane position from its points' refined disparity, and its 1-sigma [m]."""
        d0 = float(np.median(pts.d[idx]))
        # every matched pixel of the face's box within 5 % (at most a pixel) of its median disparity
        box = (int(pts.u[idx].min()), int(pts.v[idx].min()), int(pts.u[idx].max()) + 1, int(pts.v[idx].max()) + 1)
        u, v = self.stereo.matcher_for(d0).pixels_near(box, d0, min(1.0, 0.05 * d0))
        refined = refine_face(*self._pair, u, v, d0)
        if refined is None:
            return None
        d, sigma_d = refined
        # the points' x is linear in depth along each ray: x = c_x + (x_i - c_x) Z / Z_i, and Z / Z_i = d_i / d
        x = self.cam_x + (pts.x[idx] - self.cam_x) * (pts.d[idx] / d)
        # sigma_Z = Z^2 sigma_d / (f b)
        z = self.fb / d
        return float(np.median(x)), float(z * z * sigma_d / self.fb)
