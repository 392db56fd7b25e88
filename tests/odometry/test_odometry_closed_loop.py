"""The vision odometry slot in closed loop (other slots privileged), scored against the simulator's truth, and
its degraded modes: dropped frames, NaN and absurd sensor samples, black frames."""

import math

import numpy as np
import pytest

from percept.drive import DriveConfig, run_drive
from percept.odometry import OdometrySlot
from percept.sensors import Frame, ImuSample, Pose2D, StereoRig
from percept.sims import WorldConfig


@pytest.mark.slow
def test_vision_odometry_on_the_loop_keeps_within_its_bounds():
    # the first 40 s of `loop` seed 1 (about 900 m, the first bend included); the full runs (seeds 0-4 x clear,
    # night, rain, dropout, 3.5 km each) are in the README
    r = run_drive(DriveConfig(WorldConfig("loop", 1), 40.0, {"odometry": "vision"}, default="privileged"))
    o = r["odometry"]
    assert r["collisions"] == 0 and r["lane_departures"] == 0
    assert o["drift_pct_vo"] < 0.8 and o["rot_drift_deg_per_100m_vo"] < 0.3
    assert o["drift_pct_fused"] < 0.5
    assert o["drift_pct_dead_reckoning"] > o["drift_pct_fused"]
    assert o["ate_rmse_landmarks_m"] < 0.3 and o["final_error_landmarks_m"] < 0.3
    assert o["landmark_fixes"] >= 5 and o["consistency_3sigma"] >= 0.95
    assert o["path_length_m"] == pytest.approx(40.0 * 22.0, rel=0.05)
    assert r["timing_ms"]["odometry"] > 0


@pytest.mark.slow
def test_dropped_frames_widen_the_bounds_and_break_nothing():
    r = run_drive(DriveConfig(WorldConfig("loop", 2, "dropout"), 20.0, {"odometry": "vision"}, default="privileged"))
    o = r["odometry"]
    assert o["vo_failed_frames"] > 10  # 10 % of 300 frames are dropped
    traj = o.pop("trajectory")
    assert all(v is not None and math.isfinite(v) for v in o.values())
    assert len(traj["true"]) == len(traj["estimate"]) == len(range(0, 300, 15)) + 1
    assert o["consistency_3sigma"] >= 0.95 and o["ate_rmse_landmarks_m"] < 0.5


def frame(i, left=None, right=None, gyro=0.0, accel=0.0, wheel=20.0):
    return Frame(i, i / 15, left, right, ImuSample(np.array([accel, 0.0, 0.0]), np.array([0.0, 0.0, gyro])), wheel)


def test_nan_and_absurd_sensors_and_black_frames_degrade_gracefully():
    slot = OdometrySlot(StereoRig(), 1 / 15, None, Pose2D(10.0, -4.0, 0.0))
    black = np.zeros((480, 640, 3), np.uint8)
    samples = [dict(), dict(gyro=float("nan")), dict(wheel=float("nan")), dict(accel=1e9), dict(wheel=-50.0),
               dict(wheel=None), dict(left=black, right=black), dict(left=black)]
    for i, kw in enumerate(samples * 3):
        est, dbg = slot.step(frame(i, **kw), {})
        assert est.valid and np.all(np.isfinite([est.pose.x_m, est.pose.y_m, est.pose.yaw_rad, est.speed_mps]))
        assert np.all(np.isfinite(est.covariance)) and not dbg.vo_step.ok and not dbg.landmark_fix
    # NaN gyro, NaN wheel, absurd accel, absurd wheel, missing wheel: 5 rejections per filter per round, 3 filters,
    # 3 rounds
    assert dbg.rejected == 5 * 3 * 3
    # about 23 frames at 20 m/s straight ahead from (10, -4)
    assert est.pose.x_m == pytest.approx(10.0 + 20.0 * 23 / 15, abs=2.0) and abs(est.pose.y_m + 4.0) < 0.1
