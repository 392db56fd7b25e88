"""IMU and wheel-speed models: true values from the ego's kinematics plus seeded errors.

Accelerometer and gyro: white noise plus a bias random walk (the usual continuous-time model, e.g.
Woodman, *An introduction to inertial navigation*, UCAM-CL-TR-696, sec. 4). Wheel speed: a scale
error (tyre radius) and white noise.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from percept.sensors import ImuSample, wrap_angle


@dataclass(frozen=True)
class ImuNoise:
    """Error model of the simulated IMU and wheel-speed sensor."""

    accel_sigma_mps2: float = 0.05  # accelerometer white noise per sample [m/s²]
    gyro_sigma_rps: float = 0.002  # gyro white noise per sample [rad/s]
    accel_bias_walk: float = 0.002  # accelerometer bias random walk [m/s²/sqrt(s)]
    gyro_bias_walk: float = 0.0002  # gyro bias random walk [rad/s/sqrt(s)]
    wheel_sigma_mps: float = 0.05  # wheel-speed white noise per sample [m/s]
    wheel_scale_sigma: float = 0.01  # std of the fixed wheel scale error (tyre radius; 0.01 = 1 %)


class ImuModel:
    """Differentiates the ego's pose and speed into true IMU values and adds errors; one per run."""

    def __init__(self, seed: int, noise: ImuNoise = ImuNoise()):
        self.noise = noise
        self.rng = np.random.default_rng([seed, 0x1A1])
        self.wheel_scale = 1.0 + self.rng.normal(0.0, noise.wheel_scale_sigma)
        self.accel_bias = np.zeros(3)
        self.gyro_bias = np.zeros(3)
        self._prev: tuple[float, float] | None = None

    def true_sample(self, yaw_rad: float, speed_mps: float, dt: float) -> ImuSample:
        """Specific force and angular rate in the vehicle frame from consecutive (yaw, speed)."""
        if self._prev is None or dt <= 0:
            yaw_rate, accel = 0.0, 0.0
        else:
            # finite differences: r = dpsi/dt, a_x = dv/dt
            yaw_rate = float(wrap_angle(yaw_rad - self._prev[0])) / dt
            accel = (speed_mps - self._prev[1]) / dt
        self._prev = (yaw_rad, speed_mps)
        # centripetal acceleration a_y = v r (to the left for a left turn)
        return ImuSample(np.array([accel, speed_mps * yaw_rate, 0.0]), np.array([0.0, 0.0, yaw_rate]))

    def measure(self, truth: ImuSample, speed_mps: float, dt: float) -> tuple[ImuSample, float]:
        """A noisy IMU sample and wheel speed [m/s] for the true values."""
        n = self.noise
        sq = np.sqrt(max(dt, 0.0))
        self.accel_bias += self.rng.normal(0.0, n.accel_bias_walk * sq, 3)
        self.gyro_bias += self.rng.normal(0.0, n.gyro_bias_walk * sq, 3)
        acc = truth.accel_mps2 + self.accel_bias + self.rng.normal(0.0, n.accel_sigma_mps2, 3)
        gyr = truth.gyro_rps + self.gyro_bias + self.rng.normal(0.0, n.gyro_sigma_rps, 3)
        wheel = speed_mps * self.wheel_scale + self.rng.normal(0.0, n.wheel_sigma_mps)
        return ImuSample(acc, gyr), float(wheel)
