"""The constants several packages share, checked once against highway-env's own classes and percept's users."""

import numpy as np
from highway_env.vehicle.kinematics import Vehicle

from percept.sensors import LandmarkMap, StereoRig
from percept.sensors import vehicle as V


def test_ego_size_and_wheelbase_are_highway_envs():
    assert V.EGO_LENGTH_M == Vehicle.LENGTH and V.EGO_WIDTH_M == Vehicle.WIDTH
    # highway-env's bicycle: yaw rate = v sin(beta) / (L / 2), i.e. the body length is the wheelbase
    assert V.WHEELBASE_M == Vehicle.LENGTH


def test_command_limits_are_the_simulated_cars():
    from percept.sims import SimWorld, WorldConfig

    w = SimWorld(WorldConfig("highway", 0, scenery=False))
    assert w.accel_range_mps2 == V.ACCEL_RANGE_MPS2 and V.MAX_BRAKE_MPS2 == 8.0
    assert w.steer_range_rad == V.STEER_RANGE_RAD
    assert StereoRig().mount_x_m == V.CAMERA_MOUNT_X_M


def test_the_landmark_map_puts_signs_at_the_panel_centre_the_renderer_draws():
    from percept.sims import SimWorld, WorldConfig

    lm = SimWorld(WorldConfig("loop", 0, scenery=False)).landmark_map()
    assert len(lm) > 10 and np.all(lm.positions_m[:, 2] == V.SIGN_PANEL_CENTRE_M)
    assert V.SIGN_PANEL_CENTRE_M == 2.05
    again = LandmarkMap.from_dict(lm.to_dict())
    assert again.ids == lm.ids and np.array_equal(again.positions_m, lm.positions_m)
    assert lm.position(lm.ids[3]) is not None and lm.position(-1) is None


def test_bumper_gap_is_measured_from_the_front_bumper_and_never_negative():
    assert V.bumper_gap_m(10.0) == 10.0 - (2.5 - 0.8)
    assert V.bumper_gap_m(0.5) == 0.0
