"""Sky, textured ground and road paint for one camera of the rig.

The road is flat (z = 0), so each pixel below the horizon sees a fixed point of the vehicle-frame
ground plane: the ground depth map is computed once, and the world-locked grain is one perspective
warp per distance band of a mip-mapped tile (the band's level follows the pixel footprint, so the far
field is pre-filtered and does not shimmer). Road surfaces and markings are polygons on the ground
plane, projected with the ground homography (Hartley & Zisserman, sec. 8.1) and filled by OpenCV.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from percept.sensors import Pose2D, Side, StereoRig

from ..road_geometry import YELLOW, RoadGeometry
from .raster import NEAR_M
from .textures import ground_tile, mip_chain

TILE_M = 8.0
FAR_M = 220.0
"""Road paint and surfaces are drawn up to this distance ahead [m]."""
MIP_LEVELS = 6


@dataclass(frozen=True)
class Palette:
    """BGR colours of the scene's materials (0..255)."""

    sky_top: tuple = (215, 160, 105)
    sky_horizon: tuple = (235, 215, 195)
    haze: tuple = (205, 195, 185)
    grass: tuple = (70, 125, 95)
    asphalt: tuple = (105, 102, 100)
    white_paint: tuple = (235, 238, 238)
    yellow_paint: tuple = (60, 190, 225)


def _lut(color: tuple, contrast: float) -> np.ndarray:
    """256-entry colour table: albedo a -> colour * (1 + contrast (a - 128)/128)."""
    a = (np.arange(256, dtype=np.float32) - 128.0) / 128.0
    table = np.asarray(color, np.float32)[None, :] * (1.0 + contrast * a[:, None])
    return np.clip(table, 0, 255).astype(np.uint8).reshape(1, 256, 3)


class GroundLayer:
    """Precomputed background of one camera: sky, ground depth and grain bands."""

    def __init__(self, rig: StereoRig, side: Side, seed: int, palette: Palette = Palette()):
        self.rig, self.side, self.palette = rig, Side(side), palette
        cam = rig.camera
        H, W = cam.height, cam.width
        self.Hg = rig.ground_homography(self.side)
        self.Hg_inv = np.linalg.inv(self.Hg)
        # ground depth per pixel: the plane z_v = 0 in camera coordinates is n·X = d
        T = rig.cam_from_vehicle(self.side)
        n = T.R[:, 2]  # vehicle z axis in the camera frame
        d = float(n @ T.t)  # n·X = n·t for X = R p + t with p_z = 0
        rays = cam.rays()
        denom = rays @ n
        with np.errstate(divide="ignore"):
            z = d / denom
        self.ground_mask = (denom < -1e-6) & (z > 0)
        self.ground_depth = np.where(self.ground_mask, z, np.inf).astype(np.float32)
        self.first_row = int(np.argmax(self.ground_mask.any(axis=1))) if self.ground_mask.any() else H
        # sky gradient, top to horizon
        rows = np.arange(H, dtype=np.float32)
        a = np.clip(rows / max(rig.horizon_row, 1.0), 0, 1)[:, None]
        sky = (1 - a) * np.asarray(palette.sky_top, np.float32) + a * np.asarray(palette.sky_horizon, np.float32)
        self.sky = np.repeat(sky[:, None, :], W, axis=1).astype(np.uint8)
        # mip bands by pixel footprint: level = log2(texels per pixel), geometric mean of both directions
        ppm = 1024 / TILE_M
        zc = self.ground_depth[:, W // 2].astype(np.float64)
        dist = np.where(np.isfinite(zc), zc * math.cos(rig.pitch_rad), 1e6)
        lat = dist / cam.fx
        lon = np.abs(np.gradient(dist))
        with np.errstate(invalid="ignore", divide="ignore"):
            lvl = np.clip(np.round(np.log2(np.sqrt(lat * np.maximum(lon, 1e-9)) * ppm)), 0, MIP_LEVELS - 1)
        self.bands: list[tuple[int, int, int]] = []
        r = self.first_row
        while r < H:
            k = int(lvl[r]) if np.isfinite(lvl[r]) else MIP_LEVELS - 1
            r1 = r
            while r1 < H and (int(lvl[r1]) if np.isfinite(lvl[r1]) else MIP_LEVELS - 1) == k:
                r1 += 1
            self.bands.append((r, r1, k))
            r = r1
        self.mips = mip_chain(ground_tile(seed), MIP_LEVELS - 1)
        self.ppm = ppm
        # distance haze on the ground, per row
        haze = np.clip((dist - 60.0) / 400.0, 0, 0.85)
        haze[~np.isfinite(haze)] = 0.85
        self.haze_alpha = haze.astype(np.float32)
        self.lut_grass = _lut(palette.grass, 0.55)
        self.lut_asphalt = _lut(palette.asphalt, 0.35)

    def grain(self, pose: Pose2D) -> np.ndarray:
        """World-locked ground albedo (H, W) uint8 for the vehicle at ``pose`` (rows above the ground are 128)."""
        cam = self.rig.camera
        out = np.full((cam.height, cam.width), 128, np.uint8)
        # world position modulo the tile, so texture coordinates stay small
        ox = pose.x_m - TILE_M * math.floor(pose.x_m / TILE_M)
        oy = pose.y_m - TILE_M * math.floor(pose.y_m / TILE_M)
        c, s = math.cos(pose.yaw_rad), math.sin(pose.yaw_rad)
        world_from_veh = np.array([[c, -s, ox], [s, c, oy], [0, 0, 1.0]])
        for r0, r1, k in self.bands:
            scale = self.ppm / (2 ** k)
            tex_from_world = np.array([[scale, 0, 0], [0, scale, 0], [0, 0, 1.0]])
            shift = np.array([[1, 0, 0], [0, 1, r0], [0, 0, 1.0]])
            M = tex_from_world @ world_from_veh @ self.Hg_inv @ shift
            cv2.warpPerspective(self.mips[k], M, (cam.width, r1 - r0), dst=out[r0:r1],
                                flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP, borderMode=cv2.BORDER_WRAP)
        return out

    def paint(self, pose: Pose2D, road: RoadGeometry) -> tuple[np.ndarray, np.ndarray]:
        """Sky, grass, road surface and markings: image (H, W, 3) uint8 and depth (H, W) float32 [m]."""
        cam = self.rig.camera
        H, W = cam.height, cam.width
        grain = self.grain(pose)
        g3 = cv2.merge([grain, grain, grain])
        img = cv2.LUT(g3, self.lut_grass)
        road_mask = np.zeros((H, W), np.uint8)
        polys = self._surface_polygons(pose, road)
        if polys:
            cv2.fillPoly(road_mask, polys, 255, lineType=cv2.LINE_8, shift=4)
            asphalt = cv2.LUT(g3, self.lut_asphalt)
            cv2.copyTo(asphalt, road_mask, img)
        self._paint_markings(img, pose, road)
        r0 = self.first_row
        # aerial perspective: blend towards the haze colour with distance
        a = self.haze_alpha[r0:, None, None]
        img[r0:] = (img[r0:] * (1 - a) + a * np.asarray(self.palette.haze, np.float32)).astype(np.uint8)
        img[:r0] = self.sky[:r0]
        sky_rows = ~self.ground_mask
        img[sky_rows] = self.sky[sky_rows]
        return img, self.ground_depth.copy()

    def _to_image(self, xy_v: np.ndarray) -> np.ndarray:
        """Vehicle-frame ground points (..., 2) -> pixel coordinates (..., 2), fixed-point with 4 fractional bits."""
        p = xy_v @ self.Hg[:, :2].T + self.Hg[:, 2]
        uv = p[..., :2] / p[..., 2:3]
        return np.clip(np.round(uv * 16), -2**24, 2**24).astype(np.int32)

    def _surface_polygons(self, pose: Pose2D, road: RoadGeometry) -> list[np.ndarray]:
        polys = []
        near = self.rig.mount_x_m + NEAR_M
        for strip in road.strips:
            lv = pose.to_vehicle_xy(strip.left)
            rv = pose.to_vehicle_xy(strip.right)
            ok = (lv[:, 0] > near) & (rv[:, 0] > near) & (lv[:, 0] < FAR_M) & (np.abs(lv[:, 1]) < FAR_M)
            if ok.sum() < 2:
                continue
            # contiguous runs of visible samples, one polygon each
            idx = np.flatnonzero(ok)
            splits = np.flatnonzero(np.diff(idx) > 1) + 1
            for run in np.split(idx, splits):
                if len(run) < 2:
                    continue
                pts = np.concatenate([lv[run], rv[run][::-1]])
                polys.append(self._to_image(pts))
        return polys

    def _paint_markings(self, img: np.ndarray, pose: Pose2D, road: RoadGeometry) -> None:
        q = road.marking_quads
        if not len(q):
            return
        c = q.mean(axis=1)
        d = c - np.array([pose.x_m, pose.y_m])
        close = (np.abs(d[:, 0]) < FAR_M) & (np.abs(d[:, 1]) < FAR_M)
        qv = pose.to_vehicle_xy(q[close])
        near = self.rig.mount_x_m + NEAR_M
        ok = (qv[..., 0].min(axis=1) > near) & (qv[..., 0].max(axis=1) < FAR_M)
        qv = qv[ok]
        colors = road.marking_color[close][ok]
        if not len(qv):
            return
        pix = self._to_image(qv)
        for col_id, col in ((0, self.palette.white_paint), (YELLOW, self.palette.yellow_paint)):
            sel = colors == col_id
            if sel.any():
                cv2.fillPoly(img, list(pix[sel]), col, lineType=cv2.LINE_AA, shift=4)
