"""Stereo points that stand up from the road, from one rig: block matching over the image band that can hold a
vehicle within range, each matched pixel lifted to the vehicle frame.

Geometry: a left-camera pixel (u, v) with disparity d [px] is at depth Z = f b / d and (X, Y) = ((u - cx) Z / f,
(v - cy) Z / f) in the camera frame (Hartley & Zisserman, sec. 11.12); the rig's ``vehicle_from_cam`` takes it to the
vehicle frame (x forward, y left, z up), where "stands up" is a height above the road plane z = 0.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from percept.sensors import Side, StereoRig


@dataclass(frozen=True)
class PointsConfig:
    """What the band matcher looks at."""

    near_m: float = 3.5  # the nearest camera depth matched [m] (sets the disparity range)
    far_m: float = 90.0  # the farthest camera depth kept [m]
    top_m: float = 1.3  # the band's top: a vehicle's body this high above the road at the far range [m]
    low_m: float = 0.35  # the band's bottom: this high above the road at 6 m [m]
    min_height_m: float = 0.3  # a point stands up when at least this high above the road [m]
    max_height_m: float = 2.2  # and at most this high (higher: sign gantries, trees) [m]
    block: int = 7  # block-matching window, at the matching resolution [px]
    texture: int = 4  # StereoBM's texture threshold (rejects flat blocks)
    uniqueness: int = 10  # StereoBM's uniqueness ratio [%]
    shrink: int = 2  # match at 1 / shrink of the resolution (image pyramid levels: 1 or 2) [-]


@dataclass(frozen=True)
class StandingPoints:
    """The points of one rig that stand up from the road; all arrays (N,).

    u, v: left-image pixel at full resolution [px]; d: disparity at full resolution [px]; x, y, z: vehicle frame
    [m]."""

    u: np.ndarray
    v: np.ndarray
    d: np.ndarray
    x: np.ndarray
    y: np.ndarray
    z: np.ndarray

    def __len__(self) -> int:
        return len(self.u)


class BandStereo:
    """Block matching of one rig's pair over the rows where a vehicle within range stands, and the lift."""

    def __init__(self, rig: StereoRig, cfg: PointsConfig = PointsConfig()):
        self.rig, self.cfg = rig, cfg
        cam = rig.camera
        if cfg.shrink not in (1, 2):
            raise ValueError(f"shrink must be 1 or 2, got {cfg.shrink}")
        fb = cam.fx * rig.baseline_m
        # numDisparities must be a multiple of 16 covering f b / near at the matching resolution
        self.num_disp = int(np.ceil(fb / cfg.near_m / cfg.shrink / 16.0)) * 16
        self.matcher = cv2.StereoBM_create(numDisparities=self.num_disp, blockSize=cfg.block)
        self.matcher.setTextureThreshold(cfg.texture)
        self.matcher.setUniquenessRatio(cfg.uniqueness)
        hz, h = rig.horizon_row, rig.mount_height_m
        # rows of a point at height z and depth Z: v = v_horizon + f (h - z) / Z
        v_top = hz + cam.fy * (h - cfg.top_m) / cfg.far_m
        v_low = hz + cam.fy * (h - cfg.low_m) / 6.0
        k = cfg.shrink
        self.v0 = int(max(0, np.floor(min(v_top, hz - 4)) // k * k))
        self.v1 = int(min(cam.height, np.ceil(v_low / k) * k))
        R = rig.vehicle_from_cam(Side.LEFT)
        self._R, self._t = np.asarray(R.R), np.asarray(R.t)
        # the last band's disparity map at the matching resolution, ((v1 - v0) / shrink, W / shrink) int16, in
        # sixteenths of a pixel of that resolution
        self.disparity: np.ndarray | None = None

    def points(self, left_gray: np.ndarray, right_gray: np.ndarray) -> StandingPoints:
        """The standing points of one grey pair ((H, W) uint8 each)."""
        cfg, cam = self.cfg, self.rig.camera
        band = np.s_[self.v0:self.v1]
        L, R = np.ascontiguousarray(left_gray[band]), np.ascontiguousarray(right_gray[band])
        k = cfg.shrink
        if k == 2:
            L, R = cv2.pyrDown(L), cv2.pyrDown(R)
        # StereoBM gives the first num_disp columns no value: padding both images on the left by that many lets it
        # match every column whose partner is in view (a car close by in the lane to the left fills those columns)
        pad = self.num_disp
        L = cv2.copyMakeBorder(L, 0, 0, pad, 0, cv2.BORDER_REPLICATE)
        R = cv2.copyMakeBorder(R, 0, 0, pad, 0, cv2.BORDER_REPLICATE)
        disp = self.matcher.compute(L, R)[:, pad:]
        self.disparity = disp
        rows, cols = np.nonzero(disp > 0)
        # full-resolution disparity: d = shrink d_k / 16
        d = disp[rows, cols].astype(np.float32) * np.float32(k / 16.0)
        u = (cols * k).astype(np.float32)
        v = (rows * k + self.v0).astype(np.float32)
        # Z = f b / d
        Z = np.float32(cam.fx * self.rig.baseline_m) / d
        far = Z <= cfg.far_m
        u, v, d, Z = u[far], v[far], d[far], Z[far]
        # camera ray times depth: X = (u - cx) Z / f, Y = (v - cy) Z / f
        pc = np.stack([(u - cam.cx) * Z / cam.fx, (v - cam.cy) * Z / cam.fy, Z], axis=1)
        # p_v = R^T p_c + c
        pv = pc @ self._R.T.astype(np.float32) + self._t.astype(np.float32)
        up = (pv[:, 2] >= cfg.min_height_m) & (pv[:, 2] <= cfg.max_height_m)
        return StandingPoints(u[up], v[up], d[up], pv[up, 0], pv[up, 1], pv[up, 2])
