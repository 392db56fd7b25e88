"""highway-env road state -> the renderer's Scene (world frame). Works for any highway-env road."""

from __future__ import annotations

from highway_env.vehicle.kinematics import Vehicle
from highway_env.vehicle.objects import Landmark

from .actors import LaneEnd, Pedestrian, Sign
from .coords import hw_pose
from .render.scene import ObjectKind, ObjectState, Scene

VEHICLE_HEIGHT_M = 1.5


class ObjectIds:
    """Stable object ids (> 0) for a run's highway-env objects, in order of first sight."""

    def __init__(self) -> None:
        self._ids: dict[int, int] = {}
        self.objects: dict[int, object] = {}
        # the states of signs by id: they never move, so ``scene_from_road`` builds each once
        self.static_states: dict[int, ObjectState] = {}

    def __call__(self, obj) -> int:
        """The id of ``obj``, given on its first sight."""
        key = id(obj)
        if key not in self._ids:
            self._ids[key] = len(self._ids) + 1
            self.objects[self._ids[key]] = obj
        return self._ids[key]


def object_state(obj, oid: int) -> ObjectState | None:
    """The renderer's state of a highway-env road object with id ``oid`` (world frame); None for an object that is
    not drawn (highway-env's goal markers)."""
    pose = hw_pose(obj)
    if isinstance(obj, Pedestrian):
        return ObjectState(oid, ObjectKind.PEDESTRIAN, pose, obj.LENGTH, obj.WIDTH, obj.height_m, style=obj.style,
                           speed_mps=float(obj.speed), gait_phase=obj.gait_phase)
    if isinstance(obj, Sign):
        return ObjectState(oid, ObjectKind.LANDMARK, pose, obj.LENGTH, obj.WIDTH, 2.5, marker_id=obj.marker_id)
    if isinstance(obj, Vehicle):
        return ObjectState(oid, ObjectKind.VEHICLE, pose, obj.LENGTH, obj.WIDTH, VEHICLE_HEIGHT_M, style=oid * 7919,
                           speed_mps=float(obj.speed))
    if isinstance(obj, (Landmark, LaneEnd)):  # goal markers are not physical; a lane's end is where its lines end
        return None
    return ObjectState(oid, ObjectKind.VEHICLE, pose, obj.LENGTH, obj.WIDTH, 1.0, style=oid)


def scene_from_road(road, ego, ids: ObjectIds) -> Scene:
    """Snapshot every road object except the ego."""
    states = []
    for obj in list(road.vehicles) + list(road.objects):
        if obj is ego:
            continue
        oid = ids(obj)
        s = ids.static_states.get(oid)
        if s is None:
            s = object_state(obj, oid)
            if s is not None and isinstance(obj, Sign):
                ids.static_states[oid] = s
        if s is not None:
            states.append(s)
    return Scene(hw_pose(ego), tuple(states))
