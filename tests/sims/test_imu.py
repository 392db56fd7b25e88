"""ImuModel on synthetic kinematics: analytic true values, configured noise, fixed wheel scale, determinism."""

import numpy as np
import pytest

from percept.sensors import Frame, ImuSample
from percept.sims.imu import ImuModel, ImuNoise

DT = 1 / 15
QUIET = ImuNoise(0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


def kinematics(n: int, yaw0: float = 3.0, yaw_rate: float = 0.2, v0: float = 10.0, accel: float = 1.5):
    """n steps of constant yaw rate [rad/s] and acceleration [m/s^2]; yaw is wrapped to (-pi, pi]."""
    k = np.arange(n)
    yaw = np.angle(np.exp(1j * (yaw0 + yaw_rate * k * DT)))
    return yaw, v0 + accel * k * DT


def test_true_sample_matches_analytic_values_across_the_yaw_wrap():
    imu = ImuModel(0)
    yaw, speed = kinematics(60)
    assert np.any(np.diff(yaw) < -np.pi)  # the run crosses +pi -> -pi
    first = imu.true_sample(yaw[0], speed[0], DT)
    np.testing.assert_array_equal(first.accel_mps2, 0.0)  # no previous state yet
    np.testing.assert_array_equal(first.gyro_rps, 0.0)
    for y, v in zip(yaw[1:], speed[1:]):
        s = imu.true_sample(y, v, DT)
        np.testing.assert_allclose(s.gyro_rps, [0.0, 0.0, 0.2], atol=1e-9)
        # a_x = dv/dt; a_y = v r (centripetal, to the left for a left turn)
        np.testing.assert_allclose(s.accel_mps2, [1.5, v * 0.2, 0.0], atol=1e-9)
        assert s.yaw_rate_rps == pytest.approx(0.2)


def test_right_turn_gives_negative_yaw_rate_and_lateral_accel():
    imu = ImuModel(0)
    imu.true_sample(0.0, 20.0, DT)
    s = imu.true_sample(-0.1 * DT, 20.0, DT)
    assert s.yaw_rate_rps == pytest.approx(-0.1)
    assert s.accel_mps2[1] == pytest.approx(-2.0)


def test_zero_dt_gives_zero_rates():
    imu = ImuModel(0)
    imu.true_sample(0.0, 10.0, DT)
    s = imu.true_sample(0.5, 12.0, 0.0)
    assert not s.accel_mps2.any() and not s.gyro_rps.any()


def test_quiet_model_measures_the_truth_exactly():
    imu = ImuModel(3, QUIET)
    truth = ImuSample(np.array([1.0, -2.0, 0.0]), np.array([0.0, 0.0, 0.3]))
    meas, wheel = imu.measure(truth, 17.0, DT)
    np.testing.assert_array_equal(meas.accel_mps2, truth.accel_mps2)  # nothing added: the same values
    np.testing.assert_array_equal(meas.gyro_rps, truth.gyro_rps)
    assert wheel == 17.0


def _measure_many(noise: ImuNoise, n: int, seed: int = 1):
    imu = ImuModel(seed, noise)
    truth = ImuSample(np.array([1.0, -0.5, 0.0]), np.array([0.0, 0.0, 0.1]))
    acc, gyr, wheel = [], [], []
    for _ in range(n):
        m, w = imu.measure(truth, 20.0, DT)
        acc.append(m.accel_mps2)
        gyr.append(m.gyro_rps)
        wheel.append(w)
    return truth, np.array(acc), np.array(gyr), np.array(wheel), imu


def test_white_noise_mean_and_std_match_the_configuration():
    noise = ImuNoise(accel_sigma_mps2=0.05, gyro_sigma_rps=0.002, accel_bias_walk=0.0, gyro_bias_walk=0.0,
                     wheel_sigma_mps=0.05, wheel_scale_sigma=0.0)
    truth, acc, gyr, wheel, _ = _measure_many(noise, 4000)
    np.testing.assert_allclose(acc.mean(axis=0), truth.accel_mps2, atol=4 * 0.05 / np.sqrt(4000))
    np.testing.assert_allclose(gyr.mean(axis=0), truth.gyro_rps, atol=4 * 0.002 / np.sqrt(4000))
    np.testing.assert_allclose(acc.std(axis=0), 0.05, rtol=0.06)
    np.testing.assert_allclose(gyr.std(axis=0), 0.002, rtol=0.06)
    assert wheel.mean() == pytest.approx(20.0, abs=0.01)
    assert wheel.std() == pytest.approx(0.05, rel=0.06)


def test_default_noise_white_part_and_bias_walk():
    n = ImuNoise()
    _, acc, gyr, _, _ = _measure_many(n, 4000)
    # successive differences cancel the slowly wandering bias: std(diff) = sqrt(2 sigma^2 + walk^2 dt)
    expect_acc = np.sqrt(2 * n.accel_sigma_mps2 ** 2 + n.accel_bias_walk ** 2 * DT)
    expect_gyr = np.sqrt(2 * n.gyro_sigma_rps ** 2 + n.gyro_bias_walk ** 2 * DT)
    np.testing.assert_allclose(np.diff(acc, axis=0).std(axis=0), expect_acc, rtol=0.06)
    np.testing.assert_allclose(np.diff(gyr, axis=0).std(axis=0), expect_gyr, rtol=0.06)
    # bias only: each step's increment has std walk * sqrt(dt)
    walk_only = ImuNoise(0.0, 0.0, n.accel_bias_walk, n.gyro_bias_walk, 0.0, 0.0)
    _, acc, gyr, _, imu = _measure_many(walk_only, 4000)
    np.testing.assert_allclose(np.diff(acc, axis=0).std(axis=0), n.accel_bias_walk * np.sqrt(DT), rtol=0.06)
    np.testing.assert_allclose(np.diff(gyr, axis=0).std(axis=0), n.gyro_bias_walk * np.sqrt(DT), rtol=0.06)
    np.testing.assert_allclose(acc[-1] - [1.0, -0.5, 0.0], imu.accel_bias)


def test_wheel_scale_error_is_fixed_per_seed():
    noise = ImuNoise(wheel_sigma_mps=0.0)
    imu = ImuModel(5, noise)
    truth = ImuSample(np.zeros(3), np.zeros(3))
    ratios = [imu.measure(truth, v, DT)[1] / v for v in (5.0, 12.0, 30.0, 30.0, 1.0)]
    # a scale that changed with the speed would be off by about its sigma (1e-2): 1e-9 is rounding alone
    np.testing.assert_allclose(ratios, imu.wheel_scale, rtol=1e-9)
    assert ImuModel(5, noise).wheel_scale == imu.wheel_scale
    scales = np.array([ImuModel(s, noise).wheel_scale for s in range(800)])
    assert len(np.unique(scales)) == 800
    assert scales.mean() == pytest.approx(1.0, abs=0.002)
    assert scales.std() == pytest.approx(noise.wheel_scale_sigma, rel=0.1)


def _run(seed: int) -> np.ndarray:
    imu = ImuModel(seed)
    out = []
    for y, v in zip(*kinematics(50)):
        m, w = imu.measure(imu.true_sample(y, v, DT), v, DT)
        out.append(np.concatenate([m.accel_mps2, m.gyro_rps, [w]]))
    return np.array(out)


def test_deterministic_per_seed():
    np.testing.assert_array_equal(_run(7), _run(7))
    assert not np.allclose(_run(7), _run(8))


@pytest.mark.parametrize("accel, gyro", [([np.nan, 0, 0], [0, 0, 0]), ([0, 0, 0], [0, 0, np.nan]),
                                         ([np.inf, 0, 0], [0, 0, 0])])
def test_imu_sample_is_finite_detects_nan_and_inf(accel, gyro):
    assert not ImuSample(np.array(accel, float), np.array(gyro, float)).is_finite()
    assert ImuSample(np.zeros(3), np.zeros(3)).is_finite()


def test_nan_truth_propagates_into_the_measurement():
    imu = ImuModel(0)
    m, _ = imu.measure(ImuSample(np.array([np.nan, 0.0, 0.0]), np.zeros(3)), 10.0, DT)
    assert not m.is_finite()


def test_frame_dropped_when_an_image_is_missing():
    img = np.zeros((4, 4, 3), np.uint8)
    s = ImuSample(np.zeros(3), np.zeros(3))
    assert not Frame(0, 0.0, img, img, s, 0.0).dropped
    assert Frame(1, DT, None, None, s, 0.0).dropped
    assert Frame(2, 2 * DT, img, None, s, 0.0).dropped
