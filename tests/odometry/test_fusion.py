"""The pose filter on synthetic motion: a car on a circle with a biased gyro and a mis-scaled wheel sensor."""

import math

import numpy as np
import pytest

from percept.odometry import FusionNoise, PoseFilter
from percept.odometry.fusion import slip_angle
from percept.sensors import Pose2D, wrap_angle
from percept.sensors.vehicle import WHEELBASE_M

DT = 1 / 15
SPEED = 20.0
YAW_RATE = 0.04  # a 500 m radius
BIAS = 0.002
WHEEL_SCALE = 1.02


def truth(n: int) -> np.ndarray:
    """(n, 3) poses of the kinematic bicycle's centre (the model the filter assumes) at constant speed and yaw
    rate, integrated as the simulator does (explicit Euler)."""
    beta = slip_angle(YAW_RATE, SPEED, WHEELBASE_M / 2)
    out = np.zeros((n, 3))
    for k in range(1, n):
        x, y, psi = out[k - 1]
        out[k] = x + SPEED * DT * math.cos(psi + beta), y + SPEED * DT * math.sin(psi + beta), psi + YAW_RATE * DT
    return out


def drive(n: int, vo: bool, landmarks: np.ndarray | None = None, nan_every: int = 0, seed: int = 0):
    """Run a filter along ``truth(n)``; returns it, the true poses and the largest position error."""
    rng = np.random.default_rng(seed)
    path = truth(n)
    f = PoseFilter(Pose2D(0.0, 0.0, 0.0))
    worst = 0.0
    for k in range(n):
        if k:
            gyro = YAW_RATE + BIAS + rng.normal(0, 0.002)
            if nan_every and k % nan_every == 0:
                gyro = float("nan")
            f.predict(gyro, rng.normal(0, 0.05), DT)
        f.update_wheel(SPEED * WHEEL_SCALE + rng.normal(0, 0.05))
        if vo and k:
            # the true relative motion since the clone (last frame) in its vehicle frame, with 2 cm / 0.1 mrad noise
            (x0, y0, p0), (x1, y1, p1) = path[k - 1], path[k]
            c, s = math.cos(p0), math.sin(p0)
            d = np.array([c * (x1 - x0) + s * (y1 - y0), -s * (x1 - x0) + c * (y1 - y0), p1 - p0])
            d += rng.normal(0, [0.02, 0.02, 1e-4])
            f.update_relative(*d, np.diag([0.02, 0.02, 1e-4]) ** 2)
        if landmarks is not None:
            for L in landmarks:
                pose = Pose2D(*path[k])
                rel = pose.to_vehicle_xy(L[None])[0]
                if 5 < rel[0] < 30:
                    f.update_landmark(L, rel + rng.normal(0, 0.1, 2), np.eye(2) * 0.01)
        f.clone()
        worst = max(worst, math.hypot(f.pose.x_m - path[k, 0], f.pose.y_m - path[k, 1]))
    return f, path, worst


def test_dead_reckoning_drifts_with_the_wheel_scale_and_says_so():
    f, path, _ = drive(600, vo=False)
    err = math.hypot(f.pose.x_m - path[-1, 0], f.pose.y_m - path[-1, 1])
    # 2 % wheel scale over 800 m and a 0.002 rad/s bias: metres off, and the covariance admits it (3 sigma)
    assert err > 5.0
    assert err < 3 * math.sqrt(np.trace(f.pose_covariance[:2, :2]))


def test_visual_odometry_calibrates_the_wheel_scale_and_the_gyro_bias():
    f, path, worst = drive(900, vo=True)
    assert f.kf.x[5, 0] == pytest.approx(WHEEL_SCALE, abs=0.002)
    assert f.kf.x[4, 0] == pytest.approx(BIAS, abs=0.0005)
    assert worst < 3.0  # 1200 m of noisy relative motion
    assert float(wrap_angle(f.pose.yaw_rad - path[-1, 2])) == pytest.approx(0.0, abs=0.01)


def test_landmark_fixes_hold_the_position_and_a_wrong_match_is_gated():
    # signs every 80 m along the path, 8 m to either side
    path = truth(600)
    marks = np.array([p[:2] + 8.0 * (-1) ** i * np.array([-math.sin(p[2]), math.cos(p[2])])
                      for i, p in enumerate(path[60::60])])
    f, _, worst = drive(600, vo=True, landmarks=marks)
    assert worst < 0.5
    before = f.gated
    # a sign reported 6 m from where the map says: refused, the pose unchanged
    p = f.pose
    assert not f.update_landmark(np.array([p.x_m + 20.0, p.y_m]), np.array([14.0, 0.0]), np.eye(2) * 0.01)
    assert f.gated == before + 1 and f.pose == p


def test_nan_and_absurd_samples_are_rejected_never_propagated():
    f, path, worst = drive(300, vo=True, nan_every=7)
    assert f.rejected == len(range(7, 300, 7))
    assert np.all(np.isfinite(f.kf.x)) and np.all(np.isfinite(f.kf.P))
    assert worst < 1.0
    assert not f.update_wheel(float("inf")) and not f.update_wheel(-40.0)
    assert not f.update_relative(float("nan"), 0.0, 0.0, np.eye(3))
    assert f.predict(5.0, 0.0, DT) is False  # 5 rad/s: no car turns like that
    assert np.all(np.isfinite(f.kf.x))


def test_noise_settings_are_used():
    loose = PoseFilter(Pose2D(0, 0, 0), FusionNoise(wheel_scale_sigma=0.1))
    assert loose.kf.P[5, 5] == pytest.approx(0.01)


def test_a_span_that_claims_millimetres_cannot_pin_the_filter():
    """A keyframe span's relative motion that claims 2 mm (its residuals' say) is still only as good as the floor
    (FusionNoise.vo_step_floor, 3 cm along): the filter's position after it is not surer than that, so that the
    spans after it, which disagree with it by a few centimetres, are not refused by the gate."""
    f = PoseFilter(Pose2D(0.0, 0.0, 0.0))
    f.clone()
    for k in range(4):
        if k:
            f.predict(0.0, 0.0, DT)
        f.update_wheel(SPEED)
    sure = np.diag([0.002, 0.002, 1e-5]) ** 2
    assert f.update_relative(3 * DT * SPEED - 0.075, 0.0, 0.0, sure)
    along = math.sqrt(f.kf.P[0, 0])
    floor = FusionNoise().vo_step_floor[0]
    assert 0.8 * floor < along < floor
    f.clone()
    for _ in range(3):
        f.predict(0.0, 0.0, DT)
        f.update_wheel(SPEED)
    # the next span, true to the wheel, disagrees with the first by 7.5 cm: measured, not refused
    assert f.update_relative(3 * DT * SPEED, 0.0, 0.0, sure)
    assert f.gated == 0
