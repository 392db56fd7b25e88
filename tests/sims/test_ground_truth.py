"""Objects' ground truth: positions and distances in the ego's frames, and the share of each the image holds."""

import math

import numpy as np
import pytest

from percept.sensors import ObjectKind, Pose2D, Side, StereoRig
from percept.sims.ground_truth import objects_truth
from percept.sims.render import ObjectState

RIG = StereoRig()
EGO = Pose2D(50.0, -4.0, 0.3)


def placed(oid: int, ahead_m: float, left_m: float, yaw_rad: float = 0.3, kind=ObjectKind.VEHICLE) -> ObjectState:
    """An object ``ahead_m`` in front of the ego and ``left_m`` to its left (world pose from the ego's)."""
    x, y, _ = EGO.world_from_vehicle().apply(np.array([ahead_m, left_m, 0.0]))
    return ObjectState(oid, kind, Pose2D(float(x), float(y), yaw_rad), 4.8, 1.9, 1.5, speed_mps=10.0)


def truth(states, boxes=None, visible=None):
    n = len(states)
    return objects_truth(states, EGO, RIG.camera, RIG.cam_from_vehicle(Side.LEFT), boxes or [(0, 0, 1, 1)] * n,
                         visible or [1.0] * n, [False] * n)


def test_positions_yaw_and_the_nearest_face_in_the_vehicle_frame():
    (t,) = truth([placed(3, 20.0, 1.0, yaw_rad=EGO.yaw_rad + 3.0)])
    assert t.position_m == pytest.approx((20.0, 1.0, 0.75))
    # yaw relative to the ego, wrapped to [-pi, pi)
    assert t.yaw_rad == pytest.approx(3.0)
    # aligned boxes: the rear face is 2.4 m nearer than the centre; the camera sits mount_x ahead of the origin and
    # is pitched a little, so its depth of that face is close to the range along x
    along = 20.0 - 2.4 * abs(math.cos(3.0)) - 0.95 * abs(math.sin(3.0)) - RIG.mount_x_m
    assert t.distance_m == pytest.approx(along, abs=0.3)
    assert (t.size_m, t.speed_mps, t.kind) == ((4.8, 1.9, 1.5), 10.0, ObjectKind.VEHICLE)


def test_all_at_once_is_each_on_its_own_to_the_bit():
    states = [placed(1, 12.0, 0.0), placed(2, 35.0, -3.5, 1.1), placed(3, -20.0, 2.0), placed(4, 6.0, 7.0, -2.0),
              placed(5, 60.0, 0.3, 0.0, ObjectKind.PEDESTRIAN)]
    boxes = [(300, 200, 340, 260), None, None, (0, 220, 60, 300), (318, 238, 322, 246)]
    visible = [0.9, 0.0, 0.0, 0.7, 1.0]
    together = truth(states, boxes, visible)
    alone = [truth([s], [b], [v])[0] for s, b, v in zip(states, boxes, visible)]
    assert together == tuple(alone)
    assert truth([]) == ()


def test_the_visible_share_is_cut_by_the_frame_and_kept_for_objects_not_seen():
    # 10 m ahead and 4 m to the left the box crosses the image's left edge: part of it is out of the frame
    cut, whole = truth([placed(1, 10.0, 4.0, EGO.yaw_rad), placed(2, 30.0, 0.0, EGO.yaw_rad)], visible=[0.8, 0.8])
    # the rig's own projection of the box's corners: the share of their bounding box inside the image
    corners = np.array([[10.0 + a * 2.4, 4.0 + b * 0.95, h] for a in (-1, 1) for b in (-1, 1) for h in (0.0, 1.5)])
    uv, _ = RIG.project_vehicle_points(corners, Side.LEFT)
    (u0, v0), (u1, v1) = uv.min(axis=0), uv.max(axis=0)
    inside = (min(u1, RIG.camera.width) - max(u0, 0)) * (min(v1, RIG.camera.height) - max(v0, 0))
    assert u0 < 0 < u1
    assert cut.visible == pytest.approx(0.8 * inside / ((u1 - u0) * (v1 - v0)))
    assert whole.visible == pytest.approx(0.8)
    # no box (not drawn): its visible share is what the renderer said; wholly behind the camera it is 0
    (unseen,) = truth([placed(1, 6.0, 5.0, EGO.yaw_rad)], boxes=[None], visible=[0.25])
    (behind,) = truth([placed(1, -10.0, 0.0, EGO.yaw_rad)], visible=[0.5])
    assert unseen.visible == 0.25 and behind.visible == 0.0
    # beside the ego, across the camera's plane: the share of the angle it spans that the image holds (its nose)
    (beside,) = truth([placed(1, 5.0, 3.75, EGO.yaw_rad)], visible=[1.0])
    assert 0.0 < beside.visible < 0.15
