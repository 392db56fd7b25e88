"""One rig's vehicle finder: its band stereo, the ground grid's groups and each face's subpixel range."""

from __future__ import annotations

import numpy as np

from percept.sensors import LaneEstimate, Side, StereoRig

from .clusters import ClusterConfig, Detection, find_vehicles
from .points import BandStereo, PointsConfig, StandingPoints
from .refine import refine_face


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
        return find_vehicles(pts, lane, self.x_lo, self.x_hi, self.face_range, self.clusters), pts

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
