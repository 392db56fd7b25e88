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
    speckle_px: int = 30  # a matched patch of fewer pixels than this (at the matching resolution) ...
    speckle_range_px: float = 1.0  # ... whose disparity steps by no more than this inside is a speckle [px]
    drop_far_speckles: bool = True  # leave the far strip's speckles out of the points and its map (far away they
    # are phantoms), not just flag them ...
    drop_near_speckles: bool = False  # ... and the near map's (flagged, they are left out only of a group too wide
    # for a vehicle; close by, a car's lamps at night or its wet side in rain may be matched only in small patches)
    split_m: float = 32.0  # beyond this camera depth, points come from a strip matched at full resolution [m]


@dataclass(frozen=True)
class StandingPoints:
    """The points of one rig that stand up from the road; all arrays (N,).

    u, v: left-image pixel at full resolution [px]; d: disparity at full resolution [px]; x, y, z: vehicle frame
    [m]; speckle: whether the point lies in a speckle (``PointsConfig.speckle_px``), None when not told."""

    u: np.ndarray
    v: np.ndarray
    d: np.ndarray
    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    speckle: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.u)


class _Matcher:
    """StereoBM over rows v0..v1 of a pair at 1 / shrink of the resolution, padded on the left: StereoBM gives the
    first num_disp columns no value, and the padding lets it match every column whose partner is in view (a car close
    by in the lane to the left fills those columns)."""

    def __init__(self, v0: int, v1: int, shrink: int, num_disp: int, cfg: PointsConfig, drop_speckles: bool):
        self.v0, self.v1, self.shrink, self.num_disp = v0, v1, shrink, num_disp
        self.bm = cv2.StereoBM_create(numDisparities=num_disp, blockSize=cfg.block)
        self.bm.setTextureThreshold(cfg.texture)
        self.bm.setUniquenessRatio(cfg.uniqueness)
        # a speckle's disparity range in the map's units, 1/16 px
        self.speckle = (cfg.speckle_px, int(round(16 * cfg.speckle_range_px)))
        self.drop = drop_speckles
        if self.drop:  # StereoBM leaves them out of its map
            self.bm.setSpeckleWindowSize(self.speckle[0])
            self.bm.setSpeckleRange(self.speckle[1])
        self.disparity: np.ndarray | None = None  # the last map, int16 in 1/16 px of its resolution
        # the full-resolution pixels one matched pixel stands for: offsets (du, dv), each (shrink^2,) [px]
        du, dv = np.meshgrid(np.arange(shrink), np.arange(shrink))
        self._block = (du.ravel()[None, :], dv.ravel()[None, :])

    def match(self, left_gray: np.ndarray, right_gray: np.ndarray) -> tuple[np.ndarray, ...]:
        """Full-resolution (u, v, d) of every matched pixel [px], and whether it lies in a speckle: a small patch that
        sensor noise at night or a rain streak matched by chance (OpenCV's filterSpeckles; none when the matcher drops
        them)."""
        band = np.s_[self.v0:self.v1]
        L, R = np.ascontiguousarray(left_gray[band]), np.ascontiguousarray(right_gray[band])
        k, pad = self.shrink, self.num_disp
        if k == 2:
            L, R = cv2.pyrDown(L), cv2.pyrDown(R)
        L = cv2.copyMakeBorder(L, 0, 0, pad, 0, cv2.BORDER_REPLICATE)
        R = cv2.copyMakeBorder(R, 0, 0, pad, 0, cv2.BORDER_REPLICATE)
        self.disparity = np.ascontiguousarray(self.bm.compute(L, R)[:, pad:])
        rows, cols = np.nonzero(self.disparity > 0)
        # full-resolution disparity: d = shrink d_k / 16
        d = self.disparity[rows, cols].astype(np.float32) * np.float32(k / 16.0)
        if self.drop:
            return (cols * k).astype(np.float32), (rows * k + self.v0).astype(np.float32), d, np.zeros(len(d), bool)
        kept = self.disparity.copy()
        cv2.filterSpeckles(kept, 0, *self.speckle)
        speckle = kept[rows, cols] <= 0
        return (cols * k).astype(np.float32), (rows * k + self.v0).astype(np.float32), d, speckle

    def pixels_near(self, box: tuple[int, int, int, int], d0: float, tol_px: float) -> tuple[np.ndarray, np.ndarray]:
        """Full-resolution pixels (u, v) of ``box`` (u0, v0, u1, v1) whose disparity is within tol_px of d0; each
        matched pixel of a shrunk map stands for shrink x shrink of them."""
        k = self.shrink
        c0, c1 = box[0] // k, box[2] // k + 1
        r0, r1 = max(box[1] - self.v0, 0) // k, max(box[3] - self.v0, 0) // k + 1
        sub = self.disparity[r0:r1, c0:c1].astype(np.float32) * np.float32(k / 16.0)
        rows, cols = np.nonzero(np.abs(sub - np.float32(d0)) <= np.float32(tol_px))
        du, dv = self._block
        u = ((cols + c0)[:, None] * k + du).ravel()
        v = ((rows + r0)[:, None] * k + self.v0 + dv).ravel()
        return u, v


class BandStereo:
    """Block matching of one rig's pair over the rows where a vehicle within range stands, and the lift: the whole
    band at 1 / shrink of the resolution for the near points, a strip about the horizon at full resolution for the
    far ones (there a vehicle is a few pixels wide)."""

    def __init__(self, rig: StereoRig, cfg: PointsConfig = PointsConfig()):
        if cfg.shrink not in (1, 2):
            raise ValueError(f"shrink must be 1 or 2, got {cfg.shrink}")
        self.rig, self.cfg = rig, cfg
        cam = rig.camera
        fb = cam.fx * rig.baseline_m
        hz, h, k = rig.horizon_row, rig.mount_height_m, cfg.shrink
        # rows of a point at height z and depth Z: v = v_horizon + f (h - z) / Z
        v_top = int(max(0, np.floor(min(hz + cam.fy * (h - cfg.top_m) / cfg.far_m, hz - 4)) // k * k))
        v_low = int(min(cam.height, np.ceil((hz + cam.fy * (h - cfg.low_m) / 6.0) / k) * k))
        v_split = int(min(cam.height, np.ceil(hz + cam.fy * (h - cfg.low_m) / cfg.split_m) + 2))
        # numDisparities: a multiple of 16 covering f b / near at the matching resolution
        self.near = _Matcher(v_top, v_low, k, int(np.ceil(fb / cfg.near_m / k / 16.0)) * 16, cfg,
                             cfg.drop_near_speckles)
        self.far = _Matcher(v_top, v_split, 1, int(np.ceil(fb / (0.8 * cfg.split_m) / 16.0)) * 16, cfg,
                            cfg.drop_far_speckles)
        R = rig.vehicle_from_cam(Side.LEFT)
        self._R, self._t = np.asarray(R.R), np.asarray(R.t)

    def matcher_for(self, d_px: float) -> _Matcher:
        """The matcher whose points a face at full-resolution disparity d_px came from."""
        return self.far if d_px < self.rig.camera.fx * self.rig.baseline_m / self.cfg.split_m else self.near

    def points(self, left_gray: np.ndarray, right_gray: np.ndarray) -> StandingPoints:
        """The standing points of one grey pair ((H, W) uint8 each)."""
        cfg, cam = self.cfg, self.rig.camera
        fb = np.float32(cam.fx * self.rig.baseline_m)
        un, vn, dn, sn = self.near.match(left_gray, right_gray)
        uf, vf, df, sf = self.far.match(left_gray, right_gray)
        # Z = f b / d: the near map below the split depth, the strip beyond it
        keep_n, keep_f = fb / dn < cfg.split_m, (fb / df >= cfg.split_m) & (fb / df <= cfg.far_m)
        u, v, d, s = (np.concatenate([a[keep_n], b[keep_f]]) for a, b in ((un, uf), (vn, vf), (dn, df), (sn, sf)))
        Z = fb / d
        # camera ray times depth: X = (u - cx) Z / f, Y = (v - cy) Z / f
        pc = np.stack([(u - cam.cx) * Z / cam.fx, (v - cam.cy) * Z / cam.fy, Z], axis=1)
        # p_v = R^T p_c + c
        pv = pc @ self._R.T.astype(np.float32) + self._t.astype(np.float32)
        up = (pv[:, 2] >= cfg.min_height_m) & (pv[:, 2] <= cfg.max_height_m)
        return StandingPoints(u[up], v[up], d[up], pv[up, 0], pv[up, 1], pv[up, 2], s[up])
