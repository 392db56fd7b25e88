"""Plausible ego-motion samples: the one rule every slot applies to the wheel speed, the gyro and the accelerometer.

A sample that is NaN, infinite or beyond what a car on a road can do is a sensor fault, not a motion: a slot that
only needs the ego's motion (lanes, longitudinal, pedestrians) keeps the last plausible sample (``EgoMotionGate``);
the odometry filter, which weighs samples, rejects it and counts the rejection (``percept.odometry.fusion``). Both
ask the predicates here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .frame import Frame

MIN_SPEED_MPS = -1.0
"""A wheel speed below this (faster than a creep backwards) is a bad sample [m/s]."""
MAX_SPEED_MPS = 90.0
"""A wheel speed beyond this (324 km/h) is no car's but a bad sample [m/s]."""
MAX_YAW_RATE_RPS = 3.0
"""A yaw rate beyond this is no car's on a road but a bad sample [rad/s]."""
MAX_ACCEL_MPS2 = 20.0
"""A longitudinal specific force beyond this (2 g) is a bad sample [m/s^2]."""


def plausible_speed(v_mps: float) -> bool:
    """A finite wheel speed within [MIN_SPEED_MPS, MAX_SPEED_MPS]."""
    return math.isfinite(v_mps) and MIN_SPEED_MPS <= v_mps <= MAX_SPEED_MPS


def plausible_yaw_rate(w_rps: float) -> bool:
    """A finite yaw rate of at most MAX_YAW_RATE_RPS either way."""
    return math.isfinite(w_rps) and abs(w_rps) <= MAX_YAW_RATE_RPS


def plausible_accel(a_mps2: float) -> bool:
    """A finite longitudinal specific force of at most MAX_ACCEL_MPS2 either way."""
    return math.isfinite(a_mps2) and abs(a_mps2) <= MAX_ACCEL_MPS2


def as_sample(x) -> float:
    """A sensor reading ``x`` as a float, NaN when it is not a number at all (a missing sample)."""
    try:
        return float(x)
    except (TypeError, ValueError):
        return math.nan


@dataclass(frozen=True)
class EgoMotion:
    """speed_mps: the wheel speed [m/s]; yaw_rate_rps: the gyro's yaw rate [rad/s], counter-clockwise positive;
    each this frame's sample when plausible, else the last plausible one (0 before any). speed_ok, yaw_rate_ok:
    whether this frame's own sample was plausible."""

    speed_mps: float
    yaw_rate_rps: float
    speed_ok: bool
    yaw_rate_ok: bool


class EgoMotionGate:
    """``update(frame)`` -> EgoMotion: the frame's wheel speed and yaw rate, each held at the last plausible value
    while its samples are bad; ``last``: what the latest update returned; ``reset()`` forgets them."""

    def __init__(self) -> None:
        self.reset()

    def reset(self) -> None:
        self.last = EgoMotion(0.0, 0.0, False, False)

    def update(self, frame: Frame) -> EgoMotion:
        v, w = as_sample(frame.wheel_speed_mps), as_sample(frame.imu.gyro_rps[2])
        speed_ok, yaw_rate_ok = plausible_speed(v), plausible_yaw_rate(w)
        held = self.last
        self.last = EgoMotion(v if speed_ok else held.speed_mps, w if yaw_rate_ok else held.yaw_rate_rps, speed_ok,
                              yaw_rate_ok)
        return self.last
