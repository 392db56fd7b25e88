"""What the renderer draws at one instant: the ego pose and the moving or mapped objects."""

from __future__ import annotations

from dataclasses import dataclass

from percept.sensors import ObjectKind, Pose2D


@dataclass(frozen=True)
class ObjectState:
    """One object in the world frame.

    obj_id: unique id > 0 (also written into the id buffer); pose: centre on the ground, world frame;
    length_m, width_m, height_m: bounding box [m]; style: appearance seed; speed_mps [m/s];
    gait_phase: walking cycle phase [rad] (pedestrians); marker_id: ArUco id of a landmark sign's face.
    """

    obj_id: int
    kind: ObjectKind
    pose: Pose2D
    length_m: float
    width_m: float
    height_m: float
    style: int = 0
    speed_mps: float = 0.0
    gait_phase: float = 0.0
    marker_id: int | None = None


@dataclass(frozen=True)
class Scene:
    """ego: the ego vehicle's pose (world frame); objects: everything else that moves or is mapped."""

    ego: Pose2D
    objects: tuple[ObjectState, ...]
