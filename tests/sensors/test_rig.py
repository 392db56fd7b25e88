"""Analytic checks of the camera and rig models."""

import math

import numpy as np
import pytest

from percept.sensors import REAR_MOUNT_X_M, PinholeCamera, Pose2D, Side, StereoRig, rear_rig


def test_default_camera_matches_the_design():
    rig = StereoRig()
    assert (rig.camera.width, rig.camera.height) == (640, 480)
    assert math.degrees(rig.camera.hfov_rad) == pytest.approx(60.0)
    assert rig.baseline_m == 0.54 and rig.mount_height_m == 1.4


def test_projection_and_ground_homography_agree():
    rig = StereoRig(pitch_rad=0.03)
    pts = np.array([[10.0, 1.0, 0.0], [25.0, -3.0, 0.0], [60.0, 0.5, 0.0]])
    for side in Side:
        uv, z = rig.project_vehicle_points(pts, side)
        assert np.all(z > 0)
        back = rig.image_to_ground(uv, side)
        np.testing.assert_allclose(back, pts[:, :2], atol=1e-9)


def test_the_rig_computes_its_frames_once_for_its_own_pitch_and_shares_them_read_only():
    import dataclasses

    rig = StereoRig(pitch_rad=0.03)
    for side in Side:
        T = rig.cam_from_vehicle(side)
        assert T is rig.cam_from_vehicle(side.value)
        # p_c = R (p_v - c), with R the pitched axes swap
        np.testing.assert_array_equal(T.R, rig.rotation_cam_from_vehicle())  # the same function: the same bits
        np.testing.assert_allclose(T.apply(rig.camera_position(side)), 0.0, atol=1e-6)  # [m]
        # H H^-1 = I up to LAPACK's rounding on a matrix of ~1e3 px entries, whichever kernel the CPU takes
        np.testing.assert_allclose(rig.ground_homography(side) @ np.linalg.inv(rig.ground_homography(side)),
                                   np.eye(3), atol=1e-9)
        for a in (T.R, T.t, rig.ground_homography(side)):
            with pytest.raises(ValueError, match="read-only"):
                a[0] = 0.0
    # a rig made from another (dataclasses.replace) has its own pitch's frames
    steeper = dataclasses.replace(rig, pitch_rad=0.1)
    assert steeper.horizon_row < rig.horizon_row
    uv, _ = steeper.project_vehicle_points(np.array([[1e6, 0.27, 1.4]]))
    assert uv[0, 1] == pytest.approx(steeper.horizon_row, abs=1e-3)
    assert rig == StereoRig(pitch_rad=0.03)


def test_stereo_disparity_is_f_b_over_z():
    rig = StereoRig()
    p = np.array([[30.0, 0.0, 1.0]])
    ul, zl = rig.project_vehicle_points(p, Side.LEFT)
    ur, _ = rig.project_vehicle_points(p, Side.RIGHT)
    assert ul[0, 0] - ur[0, 0] == pytest.approx(rig.disparity_px(zl[0]))
    assert ul[0, 1] == pytest.approx(ur[0, 1])


def test_horizon_row_follows_pitch():
    rig = StereoRig(pitch_rad=0.05)
    uv, _ = rig.project_vehicle_points(np.array([[1e6, 0.27, 1.4]]), Side.LEFT)
    assert uv[0, 1] == pytest.approx(rig.horizon_row, abs=1e-3)
    assert rig.horizon_row < rig.camera.cy


def test_pose_round_trip():
    pose = Pose2D(5.0, -2.0, 0.7)
    p = np.array([[12.0, 3.0]])
    v = pose.to_vehicle_xy(p)
    w = pose.world_from_vehicle().apply(np.array([[v[0, 0], v[0, 1], 0.0]]))
    np.testing.assert_allclose(w[0, :2], p[0], atol=1e-6)  # [m]


def test_rig_save_load_round_trip(tmp_path):
    rig = StereoRig(baseline_m=0.3, pitch_rad=0.02)
    rig.save(tmp_path / "camera.json")
    assert StereoRig.load(tmp_path / "camera.json") == rig


def test_the_rear_rig_sits_at_the_rear_bumper_looking_back_its_left_camera_on_the_vehicles_right():
    front = StereoRig(pitch_rad=0.02)
    rear = rear_rig(front)
    assert rear.looks_back and not front.looks_back
    assert (rear.camera, rear.baseline_m, rear.pitch_rad) == (front.camera, front.baseline_m, front.pitch_rad)
    b = front.baseline_m
    # looking back, the cameras' left is the vehicle's right (-y)
    np.testing.assert_allclose(rear.camera_position(Side.LEFT), [REAR_MOUNT_X_M, -b / 2, 1.0], atol=1e-12)
    np.testing.assert_allclose(rear.camera_position(Side.RIGHT), [REAR_MOUNT_X_M, b / 2, 1.0], atol=1e-12)
    # the optical axis (camera +z) points along the vehicle's -x, pitched down; camera +x (right) along vehicle +y
    R = rear.rotation_cam_from_vehicle()
    c, s = math.cos(0.02), math.sin(0.02)
    np.testing.assert_allclose(R.T @ [0.0, 0.0, 1.0], [-c, 0.0, -s], atol=1e-12)
    np.testing.assert_allclose(R.T @ [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], atol=1e-12)


def test_a_point_behind_projects_into_the_rear_image_and_round_trips():
    rear = rear_rig(StereoRig())
    p = np.array([[-20.0, 3.0, 0.5], [-40.0, -4.0, 1.2]])
    uv, z = rear.project_vehicle_points(p, Side.LEFT)
    # straight behind along the axis: depth is the distance behind the camera
    np.testing.assert_allclose(z, -p[:, 0] + REAR_MOUNT_X_M, atol=1e-9)
    # a point to the vehicle's left (+y) is to the rear camera's right (u > cx)
    assert uv[0, 0] > rear.camera.cx > uv[1, 0]
    for side in (Side.LEFT, Side.RIGHT):
        pc = rear.cam_from_vehicle(side).apply(p)
        np.testing.assert_allclose(rear.vehicle_from_cam(side).apply(pc), p, atol=1e-12)  # [m]
    # the pair is rectified: a point's rows agree, its disparity is f b / z
    uvr, _ = rear.project_vehicle_points(p, Side.RIGHT)
    np.testing.assert_allclose(uvr[:, 1], uv[:, 1], atol=1e-9)
    np.testing.assert_allclose(uv[:, 0] - uvr[:, 0], rear.disparity_px(z), rtol=1e-9)


def test_the_rear_rig_survives_to_dict_and_from_dict_and_a_forward_rig_keeps_its_dict(tmp_path):
    rear = rear_rig(StereoRig(baseline_m=0.3, pitch_rad=0.02))
    assert StereoRig.from_dict(rear.to_dict()) == rear and rear.to_dict()["yaw_rad"] == math.pi
    rear.save(tmp_path / "rear_camera.json")
    assert StereoRig.load(tmp_path / "rear_camera.json") == rear
    assert "yaw_rad" not in StereoRig().to_dict()


@pytest.mark.parametrize("kwargs, match", [
    ({"baseline_m": 0.0}, "baseline_m must be positive"),
    ({"mount_height_m": -1.0}, "mount_height_m must be positive"),
    ({"pitch_rad": 1.0}, "pitch_rad"),
    ({"yaw_rad": math.inf}, "yaw_rad must be finite"),
])
def test_bad_rig_values_are_rejected(kwargs, match):
    with pytest.raises(ValueError, match=match):
        StereoRig(**kwargs)


def test_bad_camera_values_are_rejected(tmp_path):
    with pytest.raises(ValueError, match="focal lengths must be positive"):
        PinholeCamera(0.0, 1.0, 1.0, 1.0, 64, 64)
    with pytest.raises(ValueError, match="does not exist"):
        StereoRig.load(tmp_path / "missing.json")
