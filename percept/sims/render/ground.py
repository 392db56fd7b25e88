"""Sky, textured ground and road paint for one camera of the rig.

The road is flat (z = 0), so each pixel below the horizon sees a fixed point of the vehicle-frame
ground plane: the ground depth map is computed once, and the world-locked grain is one perspective
warp per distance band of a mip-mapped tile (the band's level follows the pixel footprint, so the far
field is pre-filtered and does not shimmer). Road surfaces and markings are polygons on the ground
plane, projected with the ground homography (Hartley & Zisserman, sec. 8.1) and filled by OpenCV.

Cost per frame: one warp per band from a pre-tiled mip level (texture coordinates stay inside the
image, OpenCV's fast path), the road surface as a mask OR-ed into the grain (grain values 0..127 are
grass, 128..255 asphalt) in the colour-map lookup (one compiled pass), the paint polygons, and haze on the
few far rows.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from percept.compiled import kernel
from percept.sensors import Pose2D, Side, StereoRig

from ..road_geometry import RoadGeometry
from .paint import GroundPaint, RoadIndex, ground_paint
from .textures import ground_tile, mip_chain

TILE_M = 8.0
TILE_PX = 1024
MIP_LEVELS = 8
"""Grain mip levels 0..7 (1024 px down to 8 px per 8 m tile); rows needing a coarser level get the mean."""
HAZE_START_M, HAZE_RANGE_M, HAZE_MAX = 60.0, 400.0, 0.85


@dataclass(frozen=True)
class Palette:
    """BGR colours (0..255) of the scene's materials."""

    sky_top: tuple = (215, 160, 105)  # the sky at the image's top row
    sky_horizon: tuple = (235, 215, 195)  # the sky at the horizon
    haze: tuple = (205, 195, 185)  # the far ground fades to it
    grass: tuple = (70, 125, 95)  # the verge, at mean albedo
    asphalt: tuple = (105, 102, 100)  # the road surface, at mean albedo
    white_paint: tuple = (235, 238, 238)  # lane lines
    yellow_paint: tuple = (60, 190, 225)  # the left road edge


def _lut(color: tuple, contrast: float) -> np.ndarray:
    """128-entry colour table for 7-bit albedo g (albedo a = 2g + 1): colour * (1 + contrast (a - 128)/128)."""
    a = (2.0 * np.arange(128, dtype=np.float32) + 1.0 - 128.0) / 128.0
    table = np.asarray(color, np.float32)[None, :] * (1.0 + contrast * a[:, None])
    return np.clip(np.round(table), 0, 255).astype(np.uint8)


@dataclass(frozen=True)
class _Band:
    """Image rows r0..r1 drawn from mip ``level``: ``tiled`` holds n x n copies of the level's tile so that
    the band's texture coordinates, shifted by whole tiles, stay inside it. centre_m: band footprint centre
    (vehicle frame), radius_m: its radius; texel_per_m: the level's scale."""

    r0: int
    r1: int
    level: int
    tiled: np.ndarray
    centre_m: np.ndarray
    radius_m: float
    texel_per_m: float


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
        # 1/Z of the ground (0 for sky): the z-buffer the rasteriser starts from
        self.ground_inv_depth = np.where(self.ground_mask, 1.0 / np.where(self.ground_mask, z, 1.0), 0.0)
        self.ground_inv_depth = self.ground_inv_depth.astype(np.float32)
        # the rig only pitches, so the horizon is a row: every row is all sky or all ground
        rows_ground = self.ground_mask.any(axis=1)
        self.first_row = int(np.argmax(rows_ground)) if rows_ground.any() else H
        if not self.ground_mask[self.first_row:].all():
            raise ValueError("GroundLayer needs a level horizon (a rig without roll)")
        rows = np.arange(H, dtype=np.float32)
        a = np.clip(rows / max(rig.horizon_row, 1.0), 0, 1)[:, None]
        sky = (1 - a) * np.asarray(palette.sky_top, np.float32) + a * np.asarray(palette.sky_horizon, np.float32)
        self.sky = np.ascontiguousarray(np.repeat(sky[:, None, :], W, axis=1).astype(np.uint8))
        self._init_bands(seed)
        # colour map of the combined grain: 0..127 grass, 128..255 asphalt
        self.cmap = np.concatenate([_lut(palette.grass, 0.55), _lut(palette.asphalt, 0.35)]).reshape(256, 1, 3)
        self._init_haze()
        self._ids = np.where(self.ground_mask, 0, -1).astype(np.int32)
        self._mask = np.zeros((H, W), np.uint8)
        self._index: tuple[RoadGeometry, RoadIndex] | None = None

    def _init_bands(self, seed: int) -> None:
        cam, rig = self.rig.camera, self.rig
        H, W = cam.height, cam.width
        r0 = self.first_row
        ppm = TILE_PX / TILE_M
        zc = self.ground_depth[:, W // 2].astype(np.float64)
        # horizontal distance along the ground of each row's centre pixel
        self.row_dist_m = np.where(np.isfinite(zc), zc * math.cos(rig.pitch_rad), np.inf)
        dist = np.where(np.isfinite(self.row_dist_m), self.row_dist_m, 1e9)
        # mip level = log2(texels per pixel), geometric mean of the lateral and longitudinal footprints
        lat = dist / cam.fx
        lon = np.abs(np.gradient(dist))
        with np.errstate(invalid="ignore", divide="ignore"):
            lvl = np.clip(np.round(np.log2(np.sqrt(lat * np.maximum(lon, 1e-9)) * ppm)), 0, MIP_LEVELS)
        lvl = lvl.astype(int)
        # vehicle-frame ground point of every ground pixel, for the band footprints
        mips = mip_chain(ground_tile(seed, TILE_PX), MIP_LEVELS - 1)
        self.bands: list[_Band] = []
        self.mean_rows: list[tuple[int, int]] = []
        """Row ranges no band covers (too far for the coarsest level): they get the tile's mean."""
        r = r0
        while r < H:
            k = int(lvl[r])
            r1 = r
            while r1 < H and int(lvl[r1]) == k:
                r1 += 1
            if k >= MIP_LEVELS:
                self.mean_rows.append((r, r1))
            else:
                # the ground homography maps the band's pixel rectangle to a quadrilateral: its corners bound it
                pts = self.rig.image_to_ground(np.array([[0, r], [W - 1, r], [0, r1 - 1], [W - 1, r1 - 1]]), self.side)
                centre = (pts.min(axis=0) + pts.max(axis=0)) / 2
                radius = float(np.linalg.norm(pts - centre, axis=1).max())
                scale = ppm / 2 ** k
                tile = mips[k] // 2  # 7-bit albedo
                # the band spans 2 radius scale texels, plus up to one tile of alignment slack and 2 for bilinear
                n = int(math.ceil((2 * radius * scale + 2) / tile.shape[0])) + 1
                self.bands.append(_Band(r, r1, k, np.tile(tile, (n, n)), centre, radius, scale))
            r = r1

    def _init_haze(self) -> None:
        # aerial perspective on the ground: colour <- colour (1 - a) + haze a, a = clip((dist - 60) / 400, 0, 0.85)
        H = self.rig.camera.height
        a = np.clip((self.row_dist_m - HAZE_START_M) / HAZE_RANGE_M, 0, HAZE_MAX)
        a[~np.isfinite(a)] = HAZE_MAX
        a[:self.first_row] = 0
        rows = np.flatnonzero(a > 0)
        self.haze_rows = (int(rows.min()), int(rows.max()) + 1) if len(rows) else (H, H)
        h0, h1 = self.haze_rows
        # fixed point with 8 fractional bits: out = (img (256 - A) + A haze) >> 8
        A = np.round(a[h0:h1] * 256).astype(np.uint16)
        self._haze_keep = (256 - A)[:, None, None]
        haze = np.asarray(self.palette.haze, np.uint16)[None, None, :]
        self._haze_add = (A[:, None, None] * haze + 128).astype(np.uint16)

    def grain(self, pose: Pose2D) -> np.ndarray:
        """World-locked 7-bit ground albedo (H - first_row, W) uint8 for the vehicle at ``pose``."""
        cam = self.rig.camera
        r0 = self.first_row
        out = np.empty((cam.height - r0, cam.width), np.uint8)
        for a, b in self.mean_rows:
            out[a - r0:b - r0] = 64
        c, s = math.cos(pose.yaw_rad), math.sin(pose.yaw_rad)
        Rz = np.array([[c, -s], [s, c]])
        # world position modulo the tile, so texture coordinates stay small
        o = np.array([pose.x_m % TILE_M, pose.y_m % TILE_M])
        for b in self.bands:
            tile_px = TILE_PX >> b.level
            # texel of the band centre; shift by whole tiles so that the band's lowest texel is >= 0
            tc = b.texel_per_m * (Rz @ b.centre_m + o)
            shift = np.floor((tc - b.texel_per_m * b.radius_m - 1) / tile_px) * tile_px
            # pixel (u, v - r0) -> ground (vehicle) -> world mod tile -> texel
            tex_from_veh = np.array([[b.texel_per_m * c, -b.texel_per_m * s, b.texel_per_m * o[0] - shift[0]],
                                     [b.texel_per_m * s, b.texel_per_m * c, b.texel_per_m * o[1] - shift[1]],
                                     [0.0, 0.0, 1.0]])
            rowshift = np.array([[1, 0, 0], [0, 1, b.r0], [0, 0, 1.0]])
            M = tex_from_veh @ self.Hg_inv @ rowshift
            cv2.warpPerspective(b.tiled, M, (cam.width, b.r1 - b.r0), dst=out[b.r0 - r0:b.r1 - r0],
                                flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP, borderMode=cv2.BORDER_REPLICATE)
        return out

    def ground_ids(self) -> np.ndarray:
        """Fresh id map of the background: 0 on the ground, -1 in the sky."""
        return self._ids.copy()

    def road_index(self, road: RoadGeometry) -> RoadIndex:
        if self._index is None or self._index[0] is not road:
            self._index = (road, RoadIndex(road))
        return self._index[1]

    def paint(self, pose: Pose2D, road: RoadGeometry, prepared: GroundPaint | None = None) -> np.ndarray:
        """Sky, grass, road surface and markings: image (H, W, 3) uint8 (its depth is ``ground_depth``).

        prepared: the road's polygons near ``pose`` (``ground_paint``), shared by the two cameras."""
        cam = self.rig.camera
        H, W = cam.height, cam.width
        r0 = self.first_row
        img = np.empty((H, W, 3), np.uint8)
        img[:r0] = self.sky[:r0]
        if r0 >= H:
            return img
        grain = self.grain(pose)
        if prepared is None:
            prepared = ground_paint(self.road_index(road), pose, self.rig, self.palette)
        surfaces, marks = prepared.project(self.Hg)
        mask = self._mask
        mask[r0:] = 0
        # one call per strip: fillPoly fills overlapping polygons of one call even-odd
        for polys in surfaces:
            cv2.fillPoly(mask, polys, 128, lineType=cv2.LINE_8, shift=4)
        _colour_map(img, grain, mask, self.cmap, r0)
        for polys, color in marks:
            cv2.fillPoly(img, polys, color, lineType=cv2.LINE_AA, shift=4)
        h0, h1 = self.haze_rows
        if h1 > h0:
            _haze(img, self._haze_keep, self._haze_add, h0)
        return img


@kernel()
def _colour_map(img, grain, mask, cmap, r0):  # pragma: no cover - compiled
    """Rows r0.. of ``img`` (H, W, 3) uint8 = ``cmap`` (256, 1, 3) of (``grain`` (H - r0, W) | ``mask``'s rows r0..):
    the road surface OR-ed into the grain and OpenCV's ``applyColorMap`` (grey to BGR, then a lookup per channel)
    in one pass."""
    for r in range(grain.shape[0]):
        for x in range(grain.shape[1]):
            g = grain[r, x] | mask[r0 + r, x]
            for ch in range(3):
                img[r0 + r, x, ch] = cmap[g, 0, ch]


@kernel()
def _haze(img, keep, add, h0):  # pragma: no cover - compiled
    """Haze on rows h0.. of ``img`` (H, W, 3) uint8, one per row of ``keep`` (n, 1, 1) and ``add`` (n, 1, 3):
    out = (img keep + add) >> 8 (``_init_haze``'s fixed point; at most 65408, so uint16 arithmetic would not
    overflow either)."""
    for r in range(keep.shape[0]):
        k = np.int64(keep[r, 0, 0])
        for x in range(img.shape[1]):
            for ch in range(3):
                img[h0 + r, x, ch] = (np.int64(img[h0 + r, x, ch]) * k + np.int64(add[r, 0, ch])) >> 8
