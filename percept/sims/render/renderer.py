"""The stereo renderer: a left and a right image (and the left depth and object-id maps) per step.

Each camera is rendered on its own from the same 3D scene, so disparities are exact: a fronto-
parallel surface at depth Z appears shifted by f·b/Z between the two images.

Per frame: the scenery patches within the view cone and within their level-of-detail reach are
selected, vehicles and signs are moved from cached templates (pedestrians are built), the road's paint
polygons are selected once for both cameras, and patches are culled and prepared once for both
(shading, level of detail and texture mip levels are shared, so both images show the same things).
Each camera then paints its ground layer and rasterises (``raster.py``, ``fragments.py``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from percept.sensors import Pose2D, Side, StereoRig

from ..road_geometry import RoadGeometry
from .grid import GroundGrid
from .ground import GroundLayer, Palette
from .fragments import PreparedPatches, WinnerMap, rasterize_prepared
from .paint import GroundPaint, ground_paint
from .patches import SUN_DIR, PatchBatch, PatchBuilder
from .pedestrian import pedestrian_packed
from .pixels import zbuffer_depth
from .raster import LOD_PX, RenderTarget, prepare, warm_up
from .scene import ObjectKind, ObjectState, Scene
from .scenery import SceneryTextures, build_scenery
from .signs import sign_patches
from .textures import TextureAtlas, building_texture, foliage_texture, marker_texture, panel_texture
from .vehicles import vehicle_patches

SCENERY_RANGE_M = 260.0
SCENERY_CELL_M = 50.0
"""Side of the cells the scenery is bucketed in for the per-frame view-cone test [m]."""
VIEW_MARGIN_RAD = 0.05
"""How far beyond half the horizontal field of view the view-cone test reaches [rad]."""
_TEMPLATE_CACHE = 1024


@dataclass(frozen=True)
class StereoImages:
    """left, right: (H, W, 3) uint8 BGR; depth_m: (H, W) float32 left-camera z [m], inf for sky (None when rendered
    without it); ids: (H, W) int32 object id per left pixel (0 road/scenery, -1 sky);
    boxes_px: obj id -> (u0, v0, u1, v1) tight box of the object's unoccluded silhouette in the left image [px],
    u1 and v1 exclusive; visible: obj id -> fraction 0..1 of that silhouette not hidden by nearer things;
    inv_depth, emission: (left, right) (H, W) float32 maps of each camera: 1/z [1/m] (0 for sky) and the
    fraction of each pixel that is a lamp (each None when rendered without it)."""

    left: np.ndarray
    right: np.ndarray
    depth_m: np.ndarray | None
    ids: np.ndarray
    boxes_px: dict
    visible: dict
    inv_depth: tuple[np.ndarray, np.ndarray] | None = None
    emission: tuple[np.ndarray, np.ndarray] | None = None


class StereoRenderer:
    """Renders a scenario's world for a stereo rig. Deterministic for a given seed. ``signs_xy`` (N, 2): landmark
    signs' world positions [m], kept clear of lamp poles."""

    def __init__(self, rig: StereoRig, road: RoadGeometry, seed: int = 0, palette: Palette = Palette(),
                 scenery: bool = True, signs_xy: np.ndarray | None = None):
        if rig.yaw_rad:
            raise ValueError(f"StereoRenderer draws a forward-looking rig (yaw_rad 0), got yaw_rad {rig.yaw_rad}; "
                             "draw a rear rig with RearRenderer")
        self.rig = rig
        self.road = road
        self.layers = {s: GroundLayer(rig, s, seed, palette) for s in (Side.LEFT, Side.RIGHT)}
        # per camera, which patch won each pixel (reused from frame to frame)
        self.winners = {s: WinnerMap((rig.camera.height, rig.camera.width)) for s in (Side.LEFT, Side.RIGHT)}
        self.road_index = self.layers[Side.LEFT].road_index(road)
        self.layers[Side.RIGHT]._index = (road, self.road_index)  # one road index for both cameras
        self.textures: list[np.ndarray] = [panel_texture(seed + 1), foliage_texture(seed + 2)]
        facades = []
        for k in range(4):
            facades.append(len(self.textures))
            self.textures.append(building_texture(seed + 10 + k))
        self._markers: dict[int, int] = {}
        self._atlas = TextureAtlas(self.textures)
        self.tex = SceneryTextures(panel=0, foliage=1, facades=tuple(facades))
        self.scenery = build_scenery(road, seed, self.tex, signs_xy) if scenery else PatchBatch.empty()
        s = self.scenery
        self._scenery_packed = s.pack()
        # bounding circle of each scenery patch on the ground (centre [m], radius [m]), for the per-frame view-cone
        # test, and the range its level of detail reaches [m]
        self.scenery_centre = (s.origin + (s.e1 + s.e2) / 2)[:, :2]
        l1, l2 = np.linalg.norm(s.e1, axis=1), np.linalg.norm(s.e2, axis=1)
        self.scenery_radius = (l1 + l2) / 2
        # beyond f min(|e1|, |e2|) / LOD_PX a patch is narrower than LOD_PX on screen, so the rasteriser skips it
        self.scenery_reach = rig.camera.fx * np.minimum(l1, l2) / LOD_PX
        self._scenery_grid = GroundGrid(self.scenery_centre, SCENERY_CELL_M)
        # the view-cone test (``scenery_in_view``) passes only patches with -r < x < RANGE + r (x = d_x - mount_x)
        # and |d_y| < (x + r) slope + r + b, r at most the largest radius: a box in the vehicle frame (1 m wider)
        self._cone_slope = slope = math.tan(rig.camera.hfov_rad / 2 + VIEW_MARGIN_RAD)
        r_max = float(self.scenery_radius.max()) if len(self.scenery_radius) else 0.0
        y_max = ((SCENERY_RANGE_M + 2 * r_max) * slope + r_max + rig.baseline_m + 1.0 if 0 < slope < math.inf
                 else math.inf)
        self._cone_box = np.array([[rig.mount_x_m - r_max - 1.0, -y_max], [rig.mount_x_m - r_max - 1.0, y_max],
                                   [rig.mount_x_m + SCENERY_RANGE_M + r_max + 1.0, -y_max],
                                   [rig.mount_x_m + SCENERY_RANGE_M + r_max + 1.0, y_max]])
        self._templates: dict[tuple, np.ndarray] = {}
        # the compiled kernels loaded (or compiled, once after an install) now, not in a timed frame: every path of
        # the rasteriser on a synthetic scene, then one frame of this road with a person on it (the road paint, the
        # haze, the figure)
        warm_up()
        self.render(Scene(Pose2D(0.0, 0.0, 0.0),
                          (ObjectState(1, ObjectKind.PEDESTRIAN, Pose2D(5.0, 0.0, 0.0), 0.5, 0.5, 1.7),)))

    @property
    def atlas(self) -> TextureAtlas:
        if self._atlas.count != len(self.textures):
            self._atlas = TextureAtlas(self.textures)
        return self._atlas

    def _marker(self, marker_id: int) -> int:
        if marker_id not in self._markers:
            self._markers[marker_id] = len(self.textures)
            self.textures.append(marker_texture(marker_id))
        return self._markers[marker_id]

    def _template(self, obj: ObjectState) -> np.ndarray:
        """The object's packed patches at the origin facing +x (cached by kind, size and style)."""
        if obj.kind is ObjectKind.VEHICLE:
            key = ("v", obj.length_m, obj.width_m, obj.height_m, obj.style)
        else:
            key = ("s", obj.length_m, obj.width_m, obj.height_m, obj.marker_id)
        t = self._templates.get(key)
        if t is None:
            b = PatchBuilder()
            at_origin = replace(obj, pose=Pose2D(0.0, 0.0, 0.0), obj_id=1)
            if obj.kind is ObjectKind.VEHICLE:
                vehicle_patches(b, at_origin, self.tex.panel)
            else:
                sign_patches(b, at_origin, self._marker(obj.marker_id if obj.marker_id is not None else 0))
            t = b.build().pack()
            if len(self._templates) >= _TEMPLATE_CACHE:
                self._templates.clear()
            self._templates[key] = t
        return t

    def _object_packed(self, scene: Scene) -> list[np.ndarray]:
        """Packed patches of the objects in range: rigid templates moved to their poses, pedestrians built."""
        people = []
        # the rig centre, between the two cameras: pedestrians' limbs face it, so both cameras see one geometry
        rig_centre = self.rig.camera_position(Side.LEFT) - [0, self.rig.baseline_m / 2, 0]
        view = scene.ego.world_from_vehicle().apply(rig_centre)
        ex, ey = scene.ego.x_m, scene.ego.y_m
        parts, poses = [], []
        for obj in scene.objects:
            if abs(obj.pose.x_m - ex) > SCENERY_RANGE_M or abs(obj.pose.y_m - ey) > SCENERY_RANGE_M:
                continue
            if obj.kind is ObjectKind.PEDESTRIAN:
                people.append(pedestrian_packed(obj, view))
                continue
            t = self._template(obj)
            parts.append(t)
            poses.append((obj.pose.x_m, obj.pose.y_m, obj.pose.yaw_rad, obj.obj_id, len(t)))
        out = []
        if parts:
            m = np.concatenate(parts)
            x, y, yaw, oid, _ = (np.repeat(np.asarray(a, float), [q[4] for q in poses]) for a in zip(*poses))
            c, s_ = np.cos(yaw), np.sin(yaw)
            # rigid move about z: points p -> R(yaw) p + (x, y, 0), directions e -> R(yaw) e
            for k in (0, 3, 6):
                px, py = m[:, k].copy(), m[:, k + 1].copy()
                m[:, k], m[:, k + 1] = c * px - s_ * py, s_ * px + c * py
            m[:, 0] += x
            m[:, 1] += y
            m[:, 14] = oid
            out.append(m)
        if people:
            out.append(np.concatenate(people))
        return out

    def object_patches(self, scene: Scene) -> PatchBatch:
        """Patches of every object in the scene, built once for both cameras."""
        parts = self._object_packed(scene)
        return PatchBatch.unpack(np.concatenate(parts)) if parts else PatchBatch.empty()

    def scenery_in_view(self, scene: Scene) -> np.ndarray:
        """Indices (ascending) of scenery whose bounding circle meets the rig's horizontal view cone, within range
        and within its level-of-detail reach; only the scenery in the grid's cells near the car is tested."""
        box = scene.ego.world_from_vehicle().apply(np.column_stack([self._cone_box, np.zeros(4)]))
        near = self._scenery_grid.within(*box[:, :2].min(axis=0), *box[:, :2].max(axis=0))
        d = scene.ego.to_vehicle_xy(self.scenery_centre[near])
        r = self.scenery_radius[near]
        x = d[:, 0] - self.rig.mount_x_m
        # |y| <= (x + r) tan(hfov/2 + margin) + r + baseline
        return near[(x + r > 0) & (x - r < np.minimum(SCENERY_RANGE_M, self.scenery_reach[near]))
                    & (np.abs(d[:, 1]) - r < (x + r) * self._cone_slope + self.rig.baseline_m)]

    def scene_patches(self, scene: Scene) -> PatchBatch:
        """Scenery in view and every object, as one batch for both cameras."""
        parts = self._object_packed(scene)
        if len(self.scenery):
            parts.insert(0, self._scenery_packed[self.scenery_in_view(scene)])
        return PatchBatch.unpack(np.concatenate(parts)) if parts else PatchBatch.empty()

    def cam_from_world(self, scene: Scene, side: Side):
        """The transform from the world frame to ``side``'s camera frame in ``scene``."""
        return self.rig.cam_from_vehicle(side).compose(scene.ego.vehicle_from_world())

    def render_side(self, scene: Scene, side: Side, patches: PatchBatch | None = None,
                    prepared_ground: GroundPaint | None = None, ids: bool = True,
                    prepared: PreparedPatches | None = None, depth: bool = True, emission: bool = True
                    ) -> RenderTarget:
        """One camera's image and, if asked, its depth, object ids and silhouettes (``ids``) and its lamp map
        (``emission``)."""
        layer = self.layers[side]
        img = layer.paint(scene.ego, self.road, prepared_ground)
        target = RenderTarget(img, None, layer.ground_ids() if ids else None, layer.ground_inv_depth.copy(),
                              layer.ground_inv_depth, np.zeros(img.shape[:2], np.float32) if emission else None,
                              winner=self.winners[side])
        if prepared is None:
            patches = self.scene_patches(scene) if patches is None else patches
            prepared = prepare(patches, self.rig.camera, [self.cam_from_world(scene, side)], self.atlas, SUN_DIR)[0]
        if prepared is not None:
            rasterize_prepared(target, prepared, self.atlas, ids)
        if depth:
            # Z = 1 / (1/Z) wherever a patch won the z-test, the ground's elsewhere
            target.depth = zbuffer_depth(target.inv_depth, target.base_inv_depth, layer.ground_depth)
        return target

    def render(self, scene: Scene, emission: bool = True, depth: bool = True) -> StereoImages:
        """Both cameras' images, the left depth, ids and boxes, and each camera's z-buffer and (``emission``) lamp
        map; without ``emission`` (nothing glows: only the night reads it) the images are the same, and without
        ``depth`` the left depth is None (the z-buffers stay)."""
        patches = self.scene_patches(scene)
        ground = ground_paint(self.road_index, scene.ego, self.rig, self.layers[Side.LEFT].palette)
        sides = (Side.LEFT, Side.RIGHT)
        prep = prepare(patches, self.rig.camera, [self.cam_from_world(scene, s) for s in sides], self.atlas, SUN_DIR)
        left = self.render_side(scene, Side.LEFT, prepared_ground=ground, prepared=prep[0], depth=depth,
                                emission=emission)
        right = self.render_side(scene, Side.RIGHT, prepared_ground=ground, ids=False, prepared=prep[1], depth=False,
                                 emission=emission)
        boxes, visible = {}, {}
        for oid in sorted(left.silhouettes):
            sil = left.silhouette(oid)
            if sil is None:
                continue
            boxes[oid] = sil[0]
            visible[oid] = min(1.0, sil[2] / sil[1])
        return StereoImages(left.image, right.image, left.depth, left.ids, boxes, visible,
                            (left.inv_depth, right.inv_depth), (left.emission, right.emission))
