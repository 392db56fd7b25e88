"""What stands in the ego path, from stereo: disparity only over the image band where the path can hold an
obstacle, each pixel lifted to the vehicle frame, and the pixels that stand up from the road inside the
corridor grouped by range; the nearest group is the obstacle.

Geometry: a left-camera pixel (u, v) with disparity d [px] is at depth Z = f b / d and
(X, Y) = ((u - cx) Z / f, (v - cy) Z / f) in the camera frame (Hartley & Zisserman, sec. 9.6 / 11.12);
the rig's transform takes it to the vehicle frame, where "stands up" is a height above the road and
"in the path" a lateral distance from the ego path's centre at that range.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from percept.sensors import EgoPath, Side, StereoRig


@dataclass(frozen=True)
class ObstacleConfig:
    """scale: image scale the coarse disparity is computed at; num_disparities / block_size: StereoBM's at that
    scale; min_range_m, max_range_m: ranges searched [m]; half_width_m: corridor half-width about the path
    centre [m]; min_height_m, max_height_m: a pixel between these heights above the road stands up [m];
    min_area_m2: smallest frontal area that counts as an obstacle [m²]; bin_rel: relative width of a range bin;
    grounded_m: a group's lowest pixels must be below this height (obstacles stand on the road; a patch of sky
    or glare matched by chance floats) [m]; texture_threshold: StereoBM's (flat regions are not matched)."""

    scale: float = 0.5
    num_disparities: int = 48
    block_size: int = 9
    min_range_m: float = 3.0
    max_range_m: float = 100.0
    half_width_m: float = 1.4
    min_height_m: float = 0.3
    max_height_m: float = 3.5
    min_area_m2: float = 0.25
    bin_rel: float = 0.04
    grounded_m: float = 1.0
    texture_threshold: int = 12

    def __post_init__(self) -> None:
        if not 0.1 <= self.scale <= 1.0:
            raise ValueError(f"scale must be in [0.1, 1], got {self.scale}")
        if self.num_disparities % 16 or self.num_disparities <= 0:
            raise ValueError(f"num_disparities must be a positive multiple of 16, got {self.num_disparities}")
        if not 0 < self.min_range_m < self.max_range_m:
            raise ValueError(f"need 0 < min_range_m < max_range_m, got {self.min_range_m}, {self.max_range_m}")


@dataclass(frozen=True)
class Obstacle:
    """The nearest group of standing pixels in the path. range_m: its median depth [m] (coarse); box_px: (u0, v0,
    u1, v1) full-resolution left-image box; support: pixels in the group; mask: (v1-v0, u1-u0) bool, which box
    pixels belong to it (coarse, upsampled); points_m: (N, 3) its pixels in the vehicle frame."""

    range_m: float
    box_px: tuple[int, int, int, int]
    support: int
    mask: np.ndarray
    points_m: np.ndarray


class ObstacleFinder:
    """Coarse disparity in the band below the horizon, lifted to the vehicle frame, filtered by the ego path."""

    def __init__(self, rig: StereoRig, cfg: ObstacleConfig = ObstacleConfig()):
        self.rig, self.cfg = rig, cfg
        cam = rig.camera
        s = cfg.scale
        self.size = (int(round(cam.width * s)), int(round(cam.height * s)))
        # rows above where the tallest obstacle at the farthest range stands are never needed
        top = rig.project_vehicle_points(np.array([[cfg.max_range_m, 0.0, cfg.max_height_m]]))[0][0, 1]
        self.row0 = max(int(np.floor(min(top, rig.horizon_row) * s)) - cfg.block_size, 0)
        self.matcher = cv2.StereoBM_create(cfg.num_disparities, cfg.block_size)
        self.matcher.setMinDisparity(0)
        self.matcher.setTextureThreshold(cfg.texture_threshold)
        self.matcher.setUniquenessRatio(10)
        h, w = self.size[1] - self.row0, self.size[0]
        vv, uu = np.mgrid[0:h, 0:w]
        # full-resolution pixel centres of the coarse grid
        self.u_full = ((uu + 0.5) / s - 0.5).astype(np.float32)
        self.v_full = ((vv + self.row0 + 0.5) / s - 0.5).astype(np.float32)
        # a pixel at depth Z is at p_v = c + Z ray, ray = R^T ((u - cx) / fx, (v - cy) / fy, 1): precomputed
        rays_c = np.stack([(self.u_full - cam.cx) / cam.fx, (self.v_full - cam.cy) / cam.fy, np.ones_like(self.u_full)],
                          axis=-1)
        self.rays = (rays_c @ rig.rotation_cam_from_vehicle()).astype(np.float32)
        self.c = rig.camera_position(Side.LEFT)

    def coarse_disparity(self, left_gray: np.ndarray, right_gray: np.ndarray) -> np.ndarray:
        """Disparity [full-resolution px] on the coarse grid of the searched band; NaN where unmatched."""
        size = self.size
        l = cv2.resize(left_gray, size, interpolation=cv2.INTER_AREA)[self.row0:]
        r = cv2.resize(right_gray, size, interpolation=cv2.INTER_AREA)[self.row0:]
        d16 = self.matcher.compute(l, r)
        d = d16.astype(np.float32) / (16.0 * self.cfg.scale)
        d[d16 <= 0] = np.nan
        return d

    def find(self, left_gray: np.ndarray, right_gray: np.ndarray, path: EgoPath) -> tuple[Obstacle | None, dict]:
        """The nearest obstacle in the path, and debug data (the coarse disparity, the standing pixels)."""
        cfg = self.cfg
        d = self.coarse_disparity(left_gray, right_gray)
        ok = np.isfinite(d) & (d > 0)
        z = np.where(ok, self.rig.camera.fx * self.rig.baseline_m / np.where(ok, d, 1.0), np.inf).astype(np.float32)
        ok &= (z > cfg.min_range_m) & (z < cfg.max_range_m)
        u, v, zc = self.u_full[ok], self.v_full[ok], z[ok]
        # camera frame: (X, Y, Z) = Z ((u - cx) / fx, (v - cy) / fy, 1); vehicle frame: p_v = R^T p_c + c
        pv = self.rays[ok] * zc[:, None] + self.c
        lateral = np.abs(pv[:, 1] - path.centre_y(pv[:, 0]))
        stand = (pv[:, 2] > cfg.min_height_m) & (pv[:, 2] < cfg.max_height_m) & (lateral < cfg.half_width_m)
        debug = {"disparity": d, "row0": self.row0, "standing": int(stand.sum())}
        if not stand.any():
            return None, debug
        return self._nearest_group(u[stand], v[stand], zc[stand], pv[stand]), debug

    def _nearest_group(self, u, v, z, pv) -> Obstacle | None:
        cfg, cam = self.cfg, self.rig.camera
        # range bins of relative width bin_rel: log(Z) in steps of log(1 + bin_rel)
        k = np.floor(np.log(z) / np.log1p(cfg.bin_rel)).astype(int)
        bins, counts = np.unique(k, return_counts=True)
        # a coarse pixel covers (Z / (f s))^2 m^2 at range Z: the support an area needs there
        need = cfg.min_area_m2 * (cam.fx * cfg.scale / np.exp(bins * np.log1p(cfg.bin_rel))) ** 2
        for b in bins[np.argsort(bins)]:
            near = np.abs(k - b) <= 1
            if near.sum() >= max(need[bins == b][0], 6) and np.percentile(pv[near, 2], 5) < cfg.grounded_m:
                sel = near
                break
        else:
            return None
        us, vs = u[sel], v[sel]
        u0, u1 = np.percentile(us, [2, 98])
        v0, v1 = np.percentile(vs, [2, 98])
        half = 0.5 / cfg.scale
        box = (int(max(u0 - half, 0)), int(max(v0 - half, 0)), int(min(u1 + half + 1, cam.width)),
               int(min(v1 + half + 1, cam.height)))
        mask = np.zeros((box[3] - box[1], box[2] - box[0]), bool)
        r = max(int(round(half)), 1)
        for uu, vv in zip(us.astype(int) - box[0], vs.astype(int) - box[1]):
            mask[max(vv - r, 0):vv + r + 1, max(uu - r, 0):uu + r + 1] = True
        return Obstacle(float(np.median(z[sel])), box, int(sel.sum()), mask, pv[sel])
