"""Landmark sightings: mapped signs' ArUco faces found in the left image, matched in the right, and their centre
measured by stereo in the vehicle frame.

The search is map-aided: from the current pose estimate, only the mapped signs that should be in view within
range are looked for, each in a window around its predicted image position widened by the pose uncertainty
(what a car with a map does; it also keeps the cost far below a whole-frame search). References: Garrido-Jurado
et al. 2014, "Automatic generation and detection of highly reliable fiducial markers under occlusion" (ArUco);
Hartley & Zisserman, sec. 12 (triangulation; for a rectified pair Z = f b / d).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from percept.sensors import LandmarkMap, Pose2D, Side, StereoRig, to_gray


ARUCO_DICTIONARY = cv2.aruco.DICT_4X4_50
MIN_PERIMETER_RATE = float(cv2.aruco.DetectorParameters().minMarkerPerimeterRate)
"""OpenCV's default ``minMarkerPerimeterRate`` (0.03): the least share of the image's longer side a marker's perimeter
needs."""


@dataclass(frozen=True)
class LandmarkSighting:
    """One mapped sign seen in both images. marker_id; position_v_m: (3,) its face centre in the vehicle frame
    [m]; covariance_xy: (2, 2) of its ground-plane position (x forward, y left) [m²]; corners_px: (4, 2) the
    marker's corners in the left image; range_m: its camera depth [m]."""

    marker_id: int
    position_v_m: np.ndarray
    covariance_xy: np.ndarray
    corners_px: np.ndarray
    range_m: float


@dataclass(frozen=True)
class SightingConfig:
    """Settings of ``LandmarkFinder``: where signs are looked for, the search windows and the sightings' errors."""

    min_range_m: float = 4.0  # least camera depth at which a sign is looked for [m]
    max_range_m: float = 32.0  # largest camera depth at which a sign is looked for [m]
    # a sighting whose corners disagree between the images gets more
    corner_sigma_px: float = 0.3  # a refined marker corner's least error [px]
    face_sigma_m: float = 0.06  # how far the face centre may lie from the mapped point (face offset, survey) [m]
    margin_px: int = 12  # added around a predicted window [px]
    sigma_window: float = 3.0  # pose-uncertainty sigmas a window covers
    marker_side_m: float = 0.63  # side of a sign's marker, its black square: 0.7 of the simulator's 0.9 m panel [m]
    # ArUco skips the smaller candidates, where most of its cost is
    min_perimeter_share: float = 0.25  # least share of the marker's expected perimeter (predicted range, face on)


class LandmarkFinder:
    """Map-aided ArUco search and stereo measurement of mapped signs for one rig."""

    def __init__(self, rig: StereoRig, landmarks: LandmarkMap, config: SightingConfig = SightingConfig()):
        self.rig, self.map, self.config = rig, landmarks, config
        self._params = cv2.aruco.DetectorParameters()
        self._params.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_SUBPIX
        self.detector = cv2.aruco.ArucoDetector(cv2.aruco.getPredefinedDictionary(ARUCO_DICTIONARY), self._params)
        self._v_from_c = rig.cam_from_vehicle(Side.LEFT).inverse()
        # the map's ground positions and heights, apart [m]
        self._map_xy, self._map_z = landmarks.positions_m[:, :2], landmarks.positions_m[:, 2]

    def expected(self, pose: Pose2D, pose_cov: np.ndarray) -> list[tuple[int, tuple[int, int, int, int], float]]:
        """Mapped signs that should be in view at ``pose``: (marker id, left-image window (u0, v0, u1, v1), the
        smallest candidate perimeter worth checking there as a share of the window's longer side)."""
        if not len(self.map):
            return []
        c = self.config
        xy = pose.to_vehicle_xy(self._map_xy)
        pts = np.empty((len(xy), 3))
        pts[:, :2] = xy
        pts[:, 2] = self._map_z
        uv, z = self.rig.project_vehicle_points(pts)
        cam = self.rig.camera
        # the pose's position uncertainty seen at depth z, and its heading uncertainty, in pixels (variances read
        # as floats: trace = var x + var y)
        pos_sigma = math.sqrt(max(pose_cov[0, 0].item() + pose_cov[1, 1].item(), 0.0))
        yaw_sigma = math.sqrt(max(pose_cov[2, 2].item(), 0.0))
        out = []
        for k, (zk, (u, v)) in enumerate(zip(z.tolist(), uv.tolist())):
            if not c.min_range_m <= zk <= c.max_range_m:
                continue
            half = c.margin_px + cam.fx * (0.6 / zk + c.sigma_window * (pos_sigma / zk + yaw_sigma))
            box = (int(max(u - half, 0)), int(max(v - half, 0)), int(min(u + half, cam.width)),
                   int(min(v + half, cam.height)))
            if box[2] - box[0] >= 16 and box[3] - box[1] >= 16:
                # the marker's perimeter face on: 4 f s / Z
                perimeter = 4.0 * cam.fx * c.marker_side_m / zk
                rate = c.min_perimeter_share * perimeter / max(box[2] - box[0], box[3] - box[1])
                out.append((self.map.ids[k], box, min(max(rate, MIN_PERIMETER_RATE), 1.0)))
        return out

    def _find(self, image: np.ndarray, box: tuple[int, int, int, int], marker_id: int,
              perimeter_rate: float = MIN_PERIMETER_RATE) -> np.ndarray | None:
        """The marker's corners (4, 2) in ``box`` of the image (BGR or grey: only the box is made grey), or None;
        candidates with a perimeter under ``perimeter_rate`` x the box's longer side are not checked."""
        u0, v0, u1, v1 = box
        self._params.minMarkerPerimeterRate = perimeter_rate
        self.detector.setDetectorParameters(self._params)
        corners, ids, _ = self.detector.detectMarkers(to_gray(image[v0:v1, u0:u1]))
        if ids is None:
            return None
        for c, i in zip(corners, ids.ravel()):
            if int(i) == marker_id:
                return c.reshape(4, 2).astype(np.float64) + (u0, v0)
        return None

    def sight(self, left: np.ndarray, right: np.ndarray, pose: Pose2D, pose_cov: np.ndarray) -> list[LandmarkSighting]:
        """Every expected sign found in both images and measured by stereo."""
        wanted = self.expected(pose, pose_cov)
        if not wanted:
            return []
        out = []
        # in the right image a sign is shifted left by its disparity: up to f b / min_range
        d_max = self.rig.disparity_px(self.config.min_range_m)
        for marker_id, box, rate in wanted:
            cl = self._find(left, box, marker_id, rate)
            if cl is None:
                continue
            rbox = (int(max(box[0] - d_max, 0)), box[1], box[2], box[3])
            # the right window is wider by the disparity range: the same perimeter, a smaller share of it
            cr = self._find(right, rbox, marker_id, rate * max(box[2] - box[0], box[3] - box[1]) / max(
                rbox[2] - rbox[0], rbox[3] - rbox[1]))
            if cr is not None:
                s = self._measure(marker_id, cl, cr)
                if s is not None:
                    out.append(s)
        return out

    def _measure(self, marker_id: int, cl: np.ndarray, cr: np.ndarray) -> LandmarkSighting | None:
        cam, c = self.rig.camera, self.config
        d = cl[:, 0] - cr[:, 0]
        # a rectified pair: the same corner on the same row, at positive disparity
        if np.any(d <= 0.5) or np.max(np.abs(cl[:, 1] - cr[:, 1])) > 2.0:
            return None
        # per corner: Z = f b / d, X = (u - cx) Z / fx, Y = (v - cy) Z / fy; the centre is their mean
        z = cam.fx * self.rig.baseline_m / d
        pc = np.column_stack([(cl[:, 0] - cam.cx) * z / cam.fx, (cl[:, 1] - cam.cy) * z / cam.fy, z]).mean(axis=0)
        if not (c.min_range_m * 0.5 <= pc[2] <= c.max_range_m * 1.5):
            return None
        zc = float(pc[2])
        # this sighting's corner error: in a rectified pair the rows of a corner in the two images differ only by
        # their errors, var(v_l - v_r) = 2 sigma^2; blur and rain streaks show there. Added to the floor:
        # sigma^2 = sigma_0^2 + mean((v_l - v_r)^2) / 2
        sigma_px = float(np.sqrt(c.corner_sigma_px ** 2 + np.mean((cl[:, 1] - cr[:, 1]) ** 2) / 2.0))
        # stereo depth error sigma_Z = Z^2 sigma_d / (f b) (sigma_d = sqrt(2) corner sigmas; four corners averaged
        # but correlated: halved, not quartered); X = (u - cx) Z / f carries Z's error along the ray:
        # Sigma_cam = J diag(sigma_u^2, sigma_v^2, sigma_Z^2) J^T, J = d(X, Y, Z) / d(u, v, Z)
        sig_z = zc ** 2 * np.sqrt(2.0) * sigma_px / (cam.fx * self.rig.baseline_m) / 2.0
        u, v = cl.mean(axis=0)
        J = np.array([[zc / cam.fx, 0.0, (u - cam.cx) / cam.fx], [0.0, zc / cam.fy, (v - cam.cy) / cam.fy],
                      [0.0, 0.0, 1.0]])
        cov_cam = J @ np.diag([sigma_px ** 2, sigma_px ** 2, sig_z ** 2]) @ J.T
        R = self._v_from_c.R
        cov_v = (R @ cov_cam @ R.T)[:2, :2] + np.eye(2) * c.face_sigma_m ** 2
        return LandmarkSighting(marker_id, self._v_from_c.apply(pc), cov_v, cl, zc)
