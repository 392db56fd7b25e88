"""What the car's sensors deliver at one instant."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class ImuSample:
    """One IMU reading in the vehicle frame (x forward, y left, z up).

    accel_mps2: (3,) specific force [m/s^2] (gravity removed: a car at rest on level ground reads ~0);
    gyro_rps: (3,) angular rate [rad/s]; yaw rate is ``gyro_rps[2]``.
    """

    accel_mps2: np.ndarray
    gyro_rps: np.ndarray

    @property
    def yaw_rate_rps(self) -> float:
        return float(self.gyro_rps[2])

    def is_finite(self) -> bool:
        return bool(np.all(np.isfinite(self.accel_mps2)) and np.all(np.isfinite(self.gyro_rps)))


@dataclass(frozen=True)
class Frame:
    """A stereo frame with inertial and wheel data.

    left, right: (H, W, 3) uint8 BGR images, or None when the frame was dropped;
    timestamp_s: time since the run started [s]; index: frame counter;
    imu: IMU sample; wheel_speed_mps: speed from the wheel encoders [m/s].
    """

    index: int
    timestamp_s: float
    left: np.ndarray | None
    right: np.ndarray | None
    imu: ImuSample
    wheel_speed_mps: float

    @property
    def dropped(self) -> bool:
        return self.left is None or self.right is None
