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

from .dense import check_num_disparities
from .ground import GroundConfig, GroundPlane
from .groups import first_grounded_blob, group_extent, range_bins, warm_up_groups
from .lift import lift_bands
from .quantiles import percentile


GROUNDED_PERCENTILE = 5
"""The percentile of a group's heights that must be below ``grounded_m`` (its lowest pixels, but for a few strays)."""


@dataclass(frozen=True)
class ObstacleConfig:
    """Settings of the obstacle finder: the two stereo bands, the corridor, what stands up and what makes a group."""

    # range splitting the two bands [m]: beyond it (the far band, rows above the road at near_m) only the columns the
    # path can reach are matched at far_scale; nearer (the rows below) the whole width at near_scale, where obstacles
    # are large
    near_m: float = 15.0
    far_scale: float = 0.5
    near_scale: float = 0.25
    num_disparities: tuple[int, int] = (48, 32)  # StereoBM's per band (far, near)
    block_size: tuple[int, int] = (9, 7)  # StereoBM's per band (far, near)
    min_range_m: float = 3.0  # nearest range searched [m]
    max_range_m: float = 100.0  # farthest range searched [m]
    half_width_m: float = 1.4  # corridor half-width about the path centre [m]
    min_height_m: float = 0.3  # a pixel higher than this above the road stands up [m]
    max_height_m: float = 3.5  # and lower than this [m]
    min_area_m2: float = 0.25  # smallest frontal area that counts as an obstacle [m²]
    bin_rel: float = 0.04  # relative width of a range bin
    # a group's lowest pixels must be below this height [m]: obstacles stand on the road, a patch of sky or glare
    # matched by chance floats
    grounded_m: float = 1.0
    texture_threshold: int = 12  # StereoBM's (flat regions are not matched)
    blob_cell_px: int = 8  # cells of the image grid in which a range group must form one connected blob [px]
    ground: GroundConfig = GroundConfig()  # the online road-plane fit (heights are measured from it)

    def __post_init__(self) -> None:
        for s in (self.far_scale, self.near_scale):
            if not 0.1 <= s <= 1.0:
                raise ValueError(f"band scales must be in [0.1, 1], got {s}")
        for n in self.num_disparities:
            check_num_disparities(n)
        if not 0 < self.min_range_m < self.near_m < self.max_range_m:
            raise ValueError(f"need 0 < min_range_m < near_m < max_range_m, got {self.min_range_m}, {self.near_m}, "
                             f"{self.max_range_m}")


@dataclass(frozen=True)
class Obstacle:
    """The nearest group of standing pixels in the path. range_m: its median depth [m] (coarse); box_px: (u0, v0,
    u1, v1) full-resolution left-image box; support: its frontal area in full-resolution pixels."""

    range_m: float
    box_px: tuple[int, int, int, int]
    support: float


class _Band:
    """StereoBM over rows [r0, r1) (full resolution) at one scale, with every coarse pixel's full-resolution centre
    and its ray precomputed: a pixel at depth Z is at p_v = c + Z ray, ray = R^T ((u - cx)/fx, (v - cy)/fy, 1)."""

    def __init__(self, rig: StereoRig, scale: float, r0: float, r1: float, nd: int, block: int, texture: int):
        cam = rig.camera
        self.s, self.nd = scale, nd
        self.r0 = max(int(np.floor(r0 * scale)), 0)
        self.r1 = min(int(np.ceil(r1 * scale)), int(round(cam.height * scale)))
        self.w = int(round(cam.width * scale))
        self.matcher = cv2.StereoBM_create(nd, block)
        self.matcher.setMinDisparity(0)
        self.matcher.setTextureThreshold(texture)
        self.matcher.setUniquenessRatio(10)
        vv, uu = np.mgrid[self.r0:self.r1, 0:self.w]
        self.u = ((uu + 0.5) / scale - 0.5).astype(np.float32)
        self.v = ((vv + 0.5) / scale - 0.5).astype(np.float32)
        rays_c = np.stack([(self.u - cam.cx) / cam.fx, (self.v - cam.cy) / cam.fy, np.ones_like(self.u)], axis=-1)
        self.rays = (rays_c @ rig.rotation_cam_from_vehicle()).astype(np.float32)
        self.fb = cam.fx * rig.baseline_m

    def shrink(self, image: np.ndarray) -> np.ndarray:
        """The band's rows of a full-resolution grey image at the band's scale: only those rows are averaged down
        (INTER_AREA at a whole-number factor averages blocks, so this equals shrinking the whole image and then
        cutting the band out of it; other factors do just that)."""
        k = round(1.0 / self.s)
        if abs(k * self.s - 1.0) > 1e-9:
            # not a whole-number factor: shrink it all, then cut
            h = int(round(image.shape[0] * self.s))
            return cv2.resize(image, (self.w, h), interpolation=cv2.INTER_AREA)[self.r0:self.r1]
        return cv2.resize(image[self.r0 * k:self.r1 * k], (self.w, self.r1 - self.r0), interpolation=cv2.INTER_AREA)

    def match(self, left: np.ndarray, right: np.ndarray, u0: float, u1: float) -> tuple:
        """The disparities of full-resolution columns [u0, u1), as ``lift_bands`` lifts them to the vehicle frame: (d16,
        c0, skip, u, v, rays, fb_scaled, area [px]); ``left``, ``right``: the band's rows at its scale (``shrink``)."""
        c0 = max(int(np.floor(u0 * self.s)) - self.nd, 0)
        c1 = min(int(np.ceil(u1 * self.s)) + 1, self.w)
        d16 = self.matcher.compute(left[:, c0:c1], right[:, c0:c1])
        skip = min(self.nd, c1 - c0) if c0 > 0 else 0  # no search room left of the crop
        # Z = f b / d with d = (d16 / 16) / s full-resolution pixels
        return d16, c0, skip, self.u, self.v, self.rays, self.fb * 16.0 * self.s, 1.0 / self.s ** 2


class ObstacleFinder:
    """Coarse disparity in two bands below the horizon, lifted to the vehicle frame, heights measured from the road
    plane refined online (``ground``), filtered by the ego path. ``reset()`` forgets the plane."""

    def __init__(self, rig: StereoRig, cfg: ObstacleConfig = ObstacleConfig()):
        self.rig, self.cfg = rig, cfg
        cam = rig.camera
        # rows above where the tallest obstacle at the farthest range stands are never needed
        top = rig.project_vehicle_points(np.array([[cfg.max_range_m, 0.0, cfg.max_height_m]]))[0][0, 1]
        split = rig.project_vehicle_points(np.array([[cfg.near_m + rig.mount_x_m, 0.0, 0.0]]))[0][0, 1]
        (nf, nn), (bf, bn) = cfg.num_disparities, cfg.block_size
        t = cfg.texture_threshold
        self.far = _Band(rig, cfg.far_scale, min(top, rig.horizon_row) - bf / cfg.far_scale, split, nf, bf, t)
        self.near = _Band(rig, cfg.near_scale, split - bn / cfg.near_scale, cam.height, nn, bn, t)
        self.c = rig.camera_position(Side.LEFT)
        self.x_far = np.linspace(cfg.near_m, cfg.max_range_m, 24) + rig.mount_x_m
        self.ground = GroundPlane(cfg.ground)
        # the compiled passes (compiled once after an install) loaded now, on a frame's argument types, not in a timed
        # frame: a black frame matches nothing, and the plane fit it starts is forgotten
        black = np.zeros((cam.height, cam.width), np.uint8)
        self.find(black, black, EgoPath.straight(0.0))
        self.reset()
        # and the group search's, which a black frame does not reach
        warm_up_groups()

    def reset(self) -> None:
        self.ground.reset()

    def _far_columns(self, path: EgoPath) -> tuple[float, float]:
        """Image columns the corridor spans beyond near_m (full resolution)."""
        y = path.centre_y(self.x_far)
        w = self.cfg.half_width_m
        pts = np.concatenate([np.column_stack([self.x_far, y + side * w, np.zeros_like(y)]) for side in (1, -1)])
        uv, _ = self.rig.project_vehicle_points(pts)
        return float(uv[:, 0].min()), float(uv[:, 0].max()) + 1

    def find(self, left_gray: np.ndarray, right_gray: np.ndarray, path: EgoPath) -> tuple[Obstacle | None, dict]:
        """The nearest obstacle in the path, and debug data (matched and standing pixel counts)."""
        cfg, cam = self.cfg, self.rig.camera
        bands = [band.match(band.shrink(left_gray), band.shrink(right_gray), u0, u1)
                 for band, (u0, u1) in ((self.far, self._far_columns(path)), (self.near, (0.0, float(cam.width))))]
        u, v, z, pv, area = lift_bands(bands, cfg.min_range_m, cfg.max_range_m, self.c)
        self.ground.update(pv, u)
        pv[:, 2] = self.ground.height(pv)
        up = np.flatnonzero((pv[:, 2] > cfg.min_height_m) & (pv[:, 2] < cfg.max_height_m))
        # the path's centre only at the points that stand up (most are the road's)
        lateral = np.abs(pv[up, 1] - path.centre_y(pv[up, 0]))
        stand = up[lateral < cfg.half_width_m]
        debug = {"matched": int(len(z)), "standing": int(len(stand))}
        if not len(stand):
            return None, debug
        return self.nearest_group(u[stand], v[stand], z[stand], pv[stand], area[stand]), debug

    def nearest_group(self, u, v, z, pv, area) -> Obstacle | None:
        """The nearest range group of the standing points (columns, rows, depths, vehicle-frame points, areas) that
        covers ``min_area_m2`` in one grounded blob, or None."""
        cfg, cam = self.cfg, self.rig.camera
        # range bins of relative width bin_rel: log(Z) in steps of log(1 + bin_rel); points sorted by bin, so that
        # bins b-1..b+1 are one slice and their area a difference of running sums
        k = np.floor(np.log(z) / np.log1p(cfg.bin_rel)).astype(int)
        order, run, bins, los, his = range_bins(k, area)
        # a full-resolution pixel covers (Z / f)^2 m^2 at range Z: the pixels an area needs there
        needs = np.maximum(cfg.min_area_m2 * (cam.fx / np.exp(bins * np.log1p(cfg.bin_rel))) ** 2, 24)
        # only bins (with their neighbours) holding that much area can hold the obstacle: nearest first
        cands = np.flatnonzero(run[his] - run[los] >= needs * (1 - 1e-4))
        found, blob = first_grounded_blob(cands, los, his, needs, order, u, v, np.ascontiguousarray(pv[:, 2]), area,
                                          cfg.blob_cell_px, GROUNDED_PERCENTILE, cfg.grounded_m)
        if found < 0:
            # two largest blobs of one area: cv2's labels say which is first
            blob = self._search(cands[-1 - found:], los, his, needs, order, u, v, pv, area)
        if not found or blob is None:
            return None
        # its box: the 2nd..98th percentiles of its columns and rows; its range: the median depth
        u0, u1, v0, v1, range_m, support = group_extent(u, v, z, area, blob)
        box = (int(max(u0 - 1, 0)), int(max(v0 - 1, 0)), int(min(u1 + 2, cam.width)), int(min(v1 + 2, cam.height)))
        return Obstacle(float(range_m), box, float(support))

    def _search(self, cands, los, his, needs, order, u, v, pv, area) -> np.ndarray | None:
        """``first_grounded_blob``'s search in numpy, where it cannot tell the largest blob: the blob's point indices,
        or None."""
        for i in cands:
            lo, hi, need = los[i], his[i], needs[i]
            near = np.sort(order[lo:hi])
            if area[near].sum() < need:
                continue
            blob = near[self._largest_blob(u[near], v[near], area[near])]
            if area[blob].sum() >= need and percentile(pv[blob, 2], GROUNDED_PERCENTILE) < self.cfg.grounded_m:
                return blob
        return None

    def _largest_blob(self, u: np.ndarray, v: np.ndarray, area: np.ndarray) -> np.ndarray:
        """Indices of the pixels of the largest connected blob (by area) among pixels (u, v) [px]: one object is
        one solid region of the image; matches scattered over it (rain streaks, noise matched by chance) are not."""
        cell = self.cfg.blob_cell_px
        cu, cv_ = (u / cell).astype(int), (v / cell).astype(int)
        grid = np.zeros((int(cv_.max()) + 2, int(cu.max()) + 2), np.uint8)
        grid[cv_, cu] = 1
        n, labels = cv2.connectedComponents(grid, connectivity=8)
        lab = labels[cv_, cu]
        best = int(np.argmax(np.bincount(lab, weights=area, minlength=n)[1:])) + 1
        return np.flatnonzero(lab == best)
