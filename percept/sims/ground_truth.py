"""Per-frame ground truth that only the simulator knows: ego, lane geometry, objects, depth, IMU."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from highway_env.utils import are_polygons_intersecting

from percept.sensors import ImuSample, ObjectKind, PinholeCamera, Pose2D, Transform, wrap_angle

from .coords import hw_to_world_yaw
from .render.scene import ObjectState


@dataclass(frozen=True)
class LaneTruth:
    """The ego lane in the vehicle frame: offset_m of the vehicle centre from the lane centre (+ left),
    heading_rad of the vehicle relative to the lane (+ CCW), curvature_1pm of the lane (+ turning left), width_m;
    lane_index: highway-env's (from, to, id), ids counting lanes from the left; beside: (left, right) whether the road
    has a lane beyond each boundary that its traffic may change into."""

    offset_m: float
    heading_rad: float
    curvature_1pm: float
    width_m: float
    lane_index: tuple
    beside: tuple = (False, False)


@dataclass(frozen=True)
class ObjectTruth:
    """kind: what it is; box_px: (u0, v0, u1, v1) in the left image or None when not seen;
    visible: 0..1 share of it the left camera sees: the unoccluded share of its silhouette in the image, times the
    share of its 3D box's projection that the image frame holds (a person half out of the frame is half visible);
    distance_m: left-camera depth of the nearest point of its
    3D box; position_m: (3,) box centre in the vehicle frame; size_m: (length, width, height); yaw_rad: heading
    relative to the ego; speed_mps; crossing: pedestrians that cross the road; marker_id: landmark sign id;
    rear_box_px, rear_visible: the same as box_px and visible for the rear rig's left camera (None and 0 without one)."""

    obj_id: int
    kind: ObjectKind
    box_px: tuple | None
    visible: float
    distance_m: float
    position_m: tuple
    size_m: tuple
    yaw_rad: float
    speed_mps: float
    crossing: bool = False
    marker_id: int | None = None
    rear_box_px: tuple | None = None
    rear_visible: float = 0.0

    def to_dict(self) -> dict:
        d = {"kind": self.kind.value, "id": self.obj_id, "box_px": list(self.box_px) if self.box_px else None,
             "visible": round(self.visible, 4), "distance_m": round(self.distance_m, 4),
             "position_m": [round(v, 4) for v in self.position_m], "size_m": list(self.size_m),
             "yaw_rad": round(self.yaw_rad, 5), "speed_mps": round(self.speed_mps, 4)}
        if self.kind is ObjectKind.PEDESTRIAN:
            d["crossing"] = self.crossing
        if self.marker_id is not None:
            d["marker_id"] = self.marker_id
        if self.rear_box_px is not None:
            d["rear_box_px"], d["rear_visible"] = list(self.rear_box_px), round(self.rear_visible, 4)
        return d


@dataclass(frozen=True)
class GroundTruth:
    """time_s; ego pose (world), speed_mps, steering_rad, accel_mps2; lane; objects; depth_m: (H, W) float32
    left-camera depth [m], inf for sky; imu: the true IMU values; crashed: the ego hit something;
    pedestrians_hit: ids of the pedestrians hit so far; collided_with: ids of the vehicles the ego touches now."""

    time_s: float
    ego: Pose2D
    speed_mps: float
    lane: LaneTruth
    objects: tuple[ObjectTruth, ...]
    depth_m: np.ndarray
    imu: ImuSample
    crashed: bool
    pedestrians_hit: tuple[int, ...]
    collided_with: tuple[int, ...] = ()

    @property
    def pedestrian_hit(self) -> bool:
        return bool(self.pedestrians_hit)

    def to_dict(self) -> dict:
        d = {
            "time_s": round(self.time_s, 4),
            "ego": {"x": self.ego.x_m, "y": self.ego.y_m, "yaw": self.ego.yaw_rad, "speed": self.speed_mps},
            "lane": {"offset_m": self.lane.offset_m, "heading_rad": self.lane.heading_rad,
                     "curvature_1pm": self.lane.curvature_1pm, "width_m": self.lane.width_m},
            "imu": {"accel_mps2": self.imu.accel_mps2.tolist(), "gyro_rps": self.imu.gyro_rps.tolist()},
            "crashed": self.crashed,
            "pedestrian_hit": self.pedestrian_hit,
            "objects": [o.to_dict() for o in self.objects],
        }
        if self.collided_with:
            d["collided_with"] = list(self.collided_with)
        return d


def lane_truth(ego) -> LaneTruth:
    """The ego's lane from highway-env's own lane geometry (local_coordinates, heading_at)."""
    lane = ego.lane
    s, lat_hw = lane.local_coordinates(ego.position)
    ds = 1.0
    # curvature = d(heading)/ds, world yaw = -heading_hw
    k = -float(wrap_angle(lane.heading_at(s + ds) - lane.heading_at(s - ds))) / (2 * ds)
    rel = float(wrap_angle(hw_to_world_yaw(ego.heading) - hw_to_world_yaw(lane.heading_at(s))))
    _from, _to, lane_id = ego.lane_index
    lanes = ego.road.network.graph[_from][_to]
    # a lane beside that the road's traffic may not enter (a ramp's acceleration lane) is none to change into
    beside = tuple(0 <= i < len(lanes) and not getattr(lanes[i], "forbidden", False)
                   for i in (lane_id - 1, lane_id + 1))
    return LaneTruth(-float(lat_hw), rel, k, float(lane.width_at(s)), tuple(ego.lane_index), beside)


_BOX_GRID = np.array([[a, b, h] for a in (-0.5, 0, 0.5) for b in (-0.5, 0, 0.5) for h in (0.0, 0.5, 1.0)])
"""Corners, edge and face centres of a box as fractions of its (length, width, height), from its base centre (27, 3)."""


def in_frame_share(camera: PinholeCamera, points_c: np.ndarray) -> np.ndarray:
    """Per object, the share of the box that bounds the projections of its points ``points_c`` (camera frame,
    (N, K, 3) [m]: K points of each of N objects) inside the image; for an object with a point behind the camera (the
    projection is not a box then: a car beside it), the share of the horizontal angle its points span that lies
    within the image's. (N,)"""
    behind = np.any(points_c[..., 2] <= 0.1, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        uv = camera.project(points_c)
    (u0, v0), (u1, v1) = uv.min(axis=1).T, uv.max(axis=1).T
    area = (u1 - u0) * (v1 - v0)
    # the part of the box inside [0, W] x [0, H]
    inside = (np.maximum(np.minimum(u1, camera.width) - np.maximum(u0, 0.0), 0.0)
              * np.maximum(np.minimum(v1, camera.height) - np.maximum(v0, 0.0), 0.0))
    ok = ~behind & ~(area <= 0)
    share = inside / np.where(ok, area, 1.0)
    if not ok.all():
        share[~ok] = _angle_share(camera, points_c[~ok])
    return share


def _angle_share(camera: PinholeCamera, points_c: np.ndarray) -> np.ndarray:
    """Per object, the share of the horizontal angle its points span (about its mean direction, so a span across the
    camera's back is whole) that the image's columns cover. (N,)"""
    # theta = atan2(x, z); the image spans atan((0 - c_x) / f_x) .. atan((W - c_x) / f_x)
    theta = np.arctan2(points_c[..., 0], points_c[..., 2])
    mid = np.arctan2(np.sin(theta).mean(axis=1), np.cos(theta).mean(axis=1))[:, None]
    theta = mid + np.angle(np.exp(1j * (theta - mid)))
    lo, hi = theta.min(axis=1), theta.max(axis=1)
    a0, a1 = np.arctan(-camera.cx / camera.fx), np.arctan((camera.width - camera.cx) / camera.fx)
    overlap = np.maximum(np.minimum(hi, a1) - np.maximum(lo, a0), 0.0)
    return np.where(hi > lo, overlap / np.where(hi > lo, hi - lo, 1.0), 1.0)


@dataclass(frozen=True)
class CameraView:
    """What one camera saw of a frame's objects: its intrinsics, its ``StereoRig.cam_from_vehicle()``, and per object
    its silhouette box (u0, v0, u1, v1) [px] or None, and the unoccluded share of that silhouette (0..1)."""

    camera: PinholeCamera
    cam_from_vehicle: Transform
    boxes_px: list
    visible: list


def _seen(view: CameraView, pts: np.ndarray) -> tuple[np.ndarray, list[float]]:
    """Per object, the camera depth of the nearest of its box points ``pts`` (N, K, 3) (vehicle frame [m]) and the
    share of it ``view``'s camera sees: the unoccluded share times the in-frame share where it has a box."""
    pc = view.cam_from_vehicle.apply(pts.reshape(-1, 3)).reshape(pts.shape)
    share = in_frame_share(view.camera, pc)
    seen = [float(v * share[k]) if view.boxes_px[k] is not None else float(v) for k, v in enumerate(view.visible)]
    return pc[..., 2].min(axis=1), seen


def objects_truth(states: list[ObjectState], ego: Pose2D, camera: PinholeCamera, cam_from_vehicle: Transform,
                  boxes_px: list, visible: list[float], crossing: list[bool],
                  rear: CameraView | None = None) -> tuple[ObjectTruth, ...]:
    """Vehicle-frame position and camera distance of each object of a frame (one entry of ``boxes_px``, ``visible``
    and ``crossing`` each); ``camera``, ``cam_from_vehicle``: the left camera's intrinsics and its
    ``StereoRig.cam_from_vehicle()``; ``rear``: what the rear rig's left camera saw (None: the car has no rear rig).
    All objects at once: the same arithmetic element by element as one by one."""
    if not states:
        return ()
    c = ego.to_vehicle_xy(np.array([[s.pose.x_m, s.pose.y_m] for s in states]))
    yaw = wrap_angle(np.array([s.pose.yaw_rad for s in states]) - ego.yaw_rad)
    # nearest point of the 3D box: sample its corners and face centres in the left camera
    cy, sy = np.cos(yaw)[:, None], np.sin(yaw)[:, None]
    size = np.array([[s.length_m, s.width_m, s.height_m] for s in states])
    local = _BOX_GRID[None] * size[:, None, :]
    pts = np.stack([c[:, :1] + cy * local[..., 0] - sy * local[..., 1], c[:, 1:] + sy * local[..., 0]
                    + cy * local[..., 1], local[..., 2]], axis=-1)
    nearest, seen = _seen(CameraView(camera, cam_from_vehicle, boxes_px, visible), pts)
    rear_boxes, rear_seen = (rear.boxes_px, _seen(rear, pts)[1]) if rear is not None else ([None] * len(states),
                                                                                          [0.0] * len(states))
    out = []
    for k, st in enumerate(states):
        L, W, H = st.length_m, st.width_m, st.height_m
        out.append(ObjectTruth(st.obj_id, st.kind, boxes_px[k], seen[k], float(nearest[k]),
                               (float(c[k, 0]), float(c[k, 1]), H / 2), (L, W, H), float(yaw[k]), st.speed_mps,
                               crossing[k], st.marker_id, rear_boxes[k], rear_seen[k]))
    return tuple(out)


def collided_with(ego, vehicles, ids, dt_s: float) -> tuple[int, ...]:
    """Ids (``ids(vehicle)``, ascending) of the ``vehicles`` the highway-env ``ego`` is in contact with: both marked
    ``crashed`` by highway-env and their rectangles meeting now or within the next ``dt_s`` [s] at their velocities
    (highway-env's own test, ``utils.are_polygons_intersecting``: it pushes colliding vehicles apart a step ahead, so
    the contact is sometimes a step away). Empty while the ego has not crashed."""
    if not ego.crashed:
        return ()
    out = []
    for v in vehicles:
        if v is ego or not v.crashed:
            continue
        # highway-env's spherical pre-check: centres further apart than the half-diagonals plus a step's travel
        if np.linalg.norm(v.position - ego.position) > (ego.diagonal + v.diagonal) / 2 + ego.speed * dt_s:
            continue
        now, soon, _ = are_polygons_intersecting(ego.polygon(), v.polygon(), ego.velocity * dt_s,
                                                 v.velocity * dt_s)
        if now or soon:
            out.append(ids(v))
    return tuple(sorted(out))
