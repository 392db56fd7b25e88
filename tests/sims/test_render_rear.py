"""The rear stereo rig drawn by the renderer: things behind the car appear where the rear rig's projection says, and
the conditions see them as a camera looking back would."""

import math

import numpy as np
import pytest

from percept.sensors import Pose2D, Side, StereoRig, rear_rig
from percept.sims.conditions import Condition, ConditionEffects
from percept.sims.render import ObjectKind, ObjectState, RearRenderer, Scene, StereoRenderer, forward_twin, turned

EGO = Pose2D(200.0, -4.0, 0.0)
"""Ego in lane 1 of highway-env's straight 4-lane road (world y = -4), heading along +x."""
REAR = rear_rig(StereoRig())


@pytest.fixture(scope="module")
def rear(road):
    return RearRenderer(REAR, road, seed=3, scenery=False)


def car(oid: int, behind_m: float, dy_m: float = 0.0, style: int = 3) -> ObjectState:
    """A car ``behind_m`` behind the ego's centre and ``dy_m`` to its left, heading the same way."""
    return ObjectState(oid, ObjectKind.VEHICLE, Pose2D(EGO.x_m - behind_m, EGO.y_m + dy_m, 0.0), 4.8, 1.9, 1.5,
                       style=style)


def test_the_twin_sees_from_the_turned_ego_what_the_rear_rig_sees():
    twin = forward_twin(REAR)
    assert twin.yaw_rad == 0.0 and twin.mount_x_m == -REAR.mount_x_m
    ego = Pose2D(12.0, -3.0, 0.4)
    for side in (Side.LEFT, Side.RIGHT):
        a = REAR.cam_from_vehicle(side).compose(ego.vehicle_from_world())
        b = twin.cam_from_vehicle(side).compose(turned(Scene(ego, ())).ego.vehicle_from_world())
        np.testing.assert_allclose(a.R, b.R, atol=1e-12)
        np.testing.assert_allclose(a.t, b.t, atol=1e-9)  # [m]


def test_renderers_refuse_rigs_they_cannot_draw(road):
    with pytest.raises(ValueError, match="looks straight back"):
        forward_twin(StereoRig(yaw_rad=math.pi / 2))
    with pytest.raises(ValueError, match="draw a rear rig with RearRenderer"):
        StereoRenderer(REAR, road, scenery=False)


@pytest.mark.parametrize("behind_m, dy_m", [(12.0, 0.0), (25.0, 4.0), (45.0, -4.0)])
def test_a_vehicle_behind_is_drawn_where_the_rear_rig_projects_it(rear, behind_m, dy_m, projected_box):
    obj = car(7, behind_m, dy_m)
    out = rear.render(Scene(EGO, (obj,)))
    # every patch that faces the rear left camera, projected with the rear rig: their bounds are the silhouette box
    expected, _, z = projected_box(obj, REAR, EGO)
    assert (z > 0).all()
    np.testing.assert_allclose(out.boxes_px[7], expected, atol=1.0)
    assert out.visible[7] == pytest.approx(1.0)
    # its front face's centre is the car in the id map, at the face's depth (x = L/2 ahead of its centre)
    face = EGO.vehicle_from_world().apply(np.array([[obj.pose.x_m + obj.length_m / 2, obj.pose.y_m, 0.6]]))
    (u, v), zf = (a[0] for a in REAR.project_vehicle_points(face, Side.LEFT))
    assert out.ids[int(v), int(u)] == 7
    assert out.depth_m[int(v), int(u)] == pytest.approx(zf, abs=0.05)


def test_nothing_ahead_of_the_car_reaches_the_rear_images(rear):
    ahead = ObjectState(9, ObjectKind.VEHICLE, Pose2D(EGO.x_m + 15.0, EGO.y_m, 0.0), 4.8, 1.9, 1.5)
    out = rear.render(Scene(EGO, (ahead,)))
    assert 9 not in out.boxes_px and not (out.ids == 9).any()


def _night(rig, renderer, scene, camera):
    img = renderer.render(scene)
    return ConditionEffects(rig, Condition.NIGHT).apply(img.left, 0, 0, camera, img.inv_depth[0], img.emission[0]), img


def test_at_night_a_following_car_shows_white_headlights_and_no_beam_lights_the_road(rig, road, rear):
    night, img = _night(REAR, rear, Scene(EGO, (car(5, 20.0),)), 2)
    u0, v0, u1, v1 = img.boxes_px[5]
    box = night[v0:v1, u0:u1].astype(int)
    lamp = img.emission[0][v0:v1, u0:u1] > 0.5
    assert lamp.sum() >= 4
    # headlights: bright and white (every channel high), not the tail lights' red
    assert np.median(box[lamp].min(axis=1)) > 200
    # the road behind is dark (ambient light only), unlike the road ahead in the ego's own beam
    ahead, _ = _night(rig, StereoRenderer(rig, road, seed=3, scenery=False), Scene(EGO, ()), 0)
    assert night[-60:].mean() < 15 < ahead[-60:].mean()


def test_a_car_ahead_at_night_shows_red_tail_lights_to_the_front_rig(rig, road):
    ahead = ObjectState(5, ObjectKind.VEHICLE, Pose2D(EGO.x_m + 20.0, EGO.y_m, 0.0), 4.8, 1.9, 1.5, style=3)
    night, img = _night(rig, StereoRenderer(rig, road, seed=3, scenery=False), Scene(EGO, (ahead,)), 0)
    u0, v0, u1, v1 = img.boxes_px[5]
    lamp = img.emission[0][v0:v1, u0:u1] > 0.5
    px = night[v0:v1, u0:u1].astype(int)[lamp]
    # BGR: red well above green and blue
    assert lamp.sum() >= 4 and np.median(px[:, 2] - px[:, 1]) > 60


def test_the_rear_camera_sees_no_sun_and_the_same_rain_noise_as_its_own(rear):
    img = rear.render(Scene(EGO, (car(5, 20.0),)), emission=False)
    assert ConditionEffects(REAR, Condition.GLARE).apply(img.left, 0, 0, 2) is img.left
    rain = ConditionEffects(REAR, Condition.RAIN)
    a, b = rain.apply(img.left, 0, 0, 2), rain.apply(img.left, 0, 0, 3)
    assert a.shape == img.left.shape and not np.array_equal(a, img.left) and not np.array_equal(a, b)
