"""Hand-made ground truth for the neighbours tests: a straight road of 4 m lanes, the ego at its lane's centre."""

import math

import numpy as np
import pytest

from percept.sensors import ImuSample, ObjectKind, Pose2D
from percept.sims.ground_truth import GroundTruth, LaneTruth, ObjectTruth

FRONT_BOX = (300, 220, 340, 250)
REAR_BOX = (280, 225, 330, 260)


def make_vehicle(obj_id: int, x: float, y: float, speed: float = 25.0, lateral_speed: float = 0.0,
                 visible: float = 1.0, rear_visible: float = 0.0, length: float = 5.0, yaw: float = 0.0) -> ObjectTruth:
    """A 5 m x 2 m car centred at (x, y) in the vehicle frame, moving at ``speed`` with ``lateral_speed`` of it
    sideways (+ left) on top of ``yaw``; its boxes exist where it is visible in that rig."""
    heading = yaw + math.asin(lateral_speed / speed) if speed else yaw
    return ObjectTruth(obj_id, ObjectKind.VEHICLE, FRONT_BOX if visible > 0 else None, visible, abs(x), (x, y, 0.75),
                       (length, 2.0, 1.5), heading, speed, rear_box_px=REAR_BOX if rear_visible > 0 else None,
                       rear_visible=rear_visible)


def make_truth(objects=(), time_s: float = 0.0, speed: float = 25.0, offset: float = 0.0, heading: float = 0.0,
               curvature: float = 0.0, width: float = 4.0, lane_index=("a", "b", 1), crashed: bool = False,
               collided_with=()) -> GroundTruth:
    """One frame's ground truth with ``objects``; the ego lane as given."""
    return GroundTruth(time_s, Pose2D(0.0, 0.0, 0.0), speed, LaneTruth(offset, heading, curvature, width, lane_index),
                       tuple(objects), np.zeros((1, 1), np.float32), ImuSample(np.zeros(3), np.zeros(3)), crashed, (),
                       tuple(collided_with))


@pytest.fixture
def vehicle():
    """``vehicle(obj_id, x, y, ...)``: a true car (``make_vehicle``)."""
    return make_vehicle


@pytest.fixture
def truth():
    """``truth(objects, ...)``: one frame's ground truth (``make_truth``)."""
    return make_truth
