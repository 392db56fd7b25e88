"""The stereo renderer: a left and a right image (and the left depth and object-id maps) per step.

Each camera is rendered on its own from the same 3D scene, so disparities are exact: a fronto-
parallel surface at depth Z appears shifted by f·b/Z between the two images.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from percept.sensors import Side, StereoRig

from ..road_geometry import RoadGeometry
from .ground import GroundLayer, Palette
from .pedestrian import pedestrian_patches
from .raster import PatchBatch, PatchBuilder, RenderTarget, rasterize
from .scene import ObjectKind, Scene
from .scenery import SceneryTextures, build_scenery
from .signs import sign_patches
from .textures import building_texture, foliage_texture, marker_texture, panel_texture
from .vehicles import vehicle_patches

SCENERY_RANGE_M = 260.0
SUN_DIR = np.array([0.35, -0.45, 0.82]) / np.linalg.norm([0.35, -0.45, 0.82])


@dataclass(frozen=True)
class StereoImages:
    """left, right: (H, W, 3) uint8 BGR; depth_m: (H, W) float32 left-camera z [m], inf for sky;
    ids: (H, W) int32 object id per left pixel (0 road/scenery, -1 sky);
    boxes_px: obj id -> (u0, v0, u1, v1) tight box of the object's unoccluded silhouette in the left image [px];
    visible: obj id -> fraction 0..1 of that silhouette not hidden by nearer things."""

    left: np.ndarray
    right: np.ndarray
    depth_m: np.ndarray
    ids: np.ndarray
    boxes_px: dict
    visible: dict


class StereoRenderer:
    """Renders a scenario's world for a stereo rig. Deterministic for a given seed."""

    def __init__(self, rig: StereoRig, road: RoadGeometry, seed: int = 0, palette: Palette = Palette(),
                 scenery: bool = True):
        self.rig = rig
        self.road = road
        self.layers = {s: GroundLayer(rig, s, seed, palette) for s in (Side.LEFT, Side.RIGHT)}
        self.textures: list[np.ndarray] = [panel_texture(seed + 1), foliage_texture(seed + 2)]
        facades = []
        for k in range(4):
            facades.append(len(self.textures))
            self.textures.append(building_texture(seed + 10 + k))
        self._markers: dict[int, int] = {}
        self.tex = SceneryTextures(panel=0, foliage=1, facades=tuple(facades))
        self.scenery = build_scenery(road, seed, self.tex) if scenery else PatchBatch.empty()
        self._scenery_centre = (self.scenery.origin + (self.scenery.e1 + self.scenery.e2) / 2)[:, :2]

    def _marker(self, marker_id: int) -> int:
        if marker_id not in self._markers:
            self._markers[marker_id] = len(self.textures)
            self.textures.append(marker_texture(marker_id))
        return self._markers[marker_id]

    def object_patches(self, scene: Scene) -> PatchBatch:
        """Patches of every object in the scene, built once for both cameras."""
        b = PatchBuilder()
        view = scene.ego.world_from_vehicle().apply(self.rig.camera_position(Side.LEFT) - [0, self.rig.baseline_m / 2, 0])
        ex, ey = scene.ego.x_m, scene.ego.y_m
        for obj in scene.objects:
            if abs(obj.pose.x_m - ex) > SCENERY_RANGE_M or abs(obj.pose.y_m - ey) > SCENERY_RANGE_M:
                continue
            if obj.kind is ObjectKind.VEHICLE:
                vehicle_patches(b, obj, self.tex.panel)
            elif obj.kind is ObjectKind.PEDESTRIAN:
                pedestrian_patches(b, obj, view)
            elif obj.kind is ObjectKind.LANDMARK:
                sign_patches(b, obj, self._marker(obj.marker_id if obj.marker_id is not None else 0))
        return b.build()

    def _visible_scenery(self, scene: Scene) -> PatchBatch:
        if not len(self.scenery):
            return self.scenery
        d = scene.ego.to_vehicle_xy(self._scenery_centre)
        keep = (d[:, 0] > -40.0) & (d[:, 0] < SCENERY_RANGE_M) & (np.abs(d[:, 1]) < SCENERY_RANGE_M)
        s = self.scenery
        return PatchBatch(*[getattr(s, f)[keep] for f in PatchBatch.__dataclass_fields__])

    def render_side(self, scene: Scene, side: Side, patches: PatchBatch) -> RenderTarget:
        img, depth = self.layers[side].paint(scene.ego, self.road)
        ids = np.where(np.isfinite(depth), 0, -1).astype(np.int32)
        target = RenderTarget(img, depth, ids)
        cam_from_world = self.rig.cam_from_vehicle(side).compose(scene.ego.vehicle_from_world())
        rasterize(target, patches, self.rig.camera, cam_from_world, self.textures, SUN_DIR)
        return target

    def render(self, scene: Scene) -> StereoImages:
        patches = PatchBatch.concat([self._visible_scenery(scene), self.object_patches(scene)])
        left = self.render_side(scene, Side.LEFT, patches)
        right = self.render_side(scene, Side.RIGHT, patches)
        boxes, visible = {}, {}
        counts = np.bincount(left.ids[left.ids > 0].ravel()) if (left.ids > 0).any() else np.zeros(1, int)
        for oid in left.pieces:
            sil = left.silhouette_px(oid)
            if sil == 0:
                continue
            boxes[oid] = _silhouette_box(left.pieces[oid])
            seen = int(counts[oid]) if oid < len(counts) else 0
            visible[oid] = min(1.0, seen / sil)
        return StereoImages(left.image, right.image, left.depth, left.ids, boxes, visible)


def _silhouette_box(parts: list) -> tuple[int, int, int, int]:
    """Tight (u0, v0, u1, v1) of the union of an object's patch masks; u1, v1 exclusive."""
    u0 = v0 = 10**9
    u1 = v1 = -1
    for x0, y0, m in parts:
        rows = np.flatnonzero(m.any(axis=1))
        cols = np.flatnonzero(m.any(axis=0))
        if not len(rows):
            continue
        u0, u1 = min(u0, x0 + cols[0]), max(u1, x0 + cols[-1] + 1)
        v0, v1 = min(v0, y0 + rows[0]), max(v1, y0 + rows[-1] + 1)
    return int(u0), int(v0), int(u1), int(v1)
