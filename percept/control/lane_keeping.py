"""Lane keeping: steering from the ego path's offset, heading and curvature (shared by privileged and vision slots).

Lateral error dynamics of a path-following car: y' = v sin(theta), theta' = v (kappa_cmd - kappa_lane).
Choosing kappa_cmd = kappa_lane - 2 w sin(theta) / v - w^2 y / v^2 gives y'' + 2 w y' + w^2 y = 0:
critically damped with time constant T = 1/w (Rajamani, *Vehicle Dynamics and Control*, 2nd ed., ch. 3).
Following a lateral reference r(t) (a lane change's path, ``lateral_path``) the error e = y - r obeys the same
equation with kappa_cmd = kappa_lane + (r'' - 2 w (v sin(theta) - r') - w^2 (y - r)) / v^2. A reference may bound the
lateral jerk, v^2 d(kappa)/dt: the command's curvature then moves by at most j_max dt / v^2 a frame, so that a lane
estimate's frame-to-frame jitter, through the feedback, does not jerk the car during a lane change.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from percept.sensors import EgoPath
from percept.sensors.vehicle import STEER_RANGE_RAD

from .base import Controller, sideslip_for_curvature, steering_for_curvature
from .lateral_path import LateralRef


@dataclass(frozen=True)
class LaneKeepingDebug:
    """How the lane-keeping law made its command: the curvature terms it adds up and the steering they give."""

    feedforward_1pm: float  # the lane's own curvature [1/m]
    offset_1pm: float  # the offset feedback term, -w^2 (y - r) / v^2 [1/m]
    heading_1pm: float  # the heading feedback term, -2 w (v sin(theta) - r') / v^2 [1/m]
    steering_rad: float  # the front-wheel angle asked for, before the vehicle's steering range [rad]
    limited_by: str  # "path" (no lane: hold straight), "jerk" (the reference's jerk bound), "steer_limit" (outside
    # the steering range) or "none"
    reference_1pm: float = 0.0  # the reference's own term, r'' / v^2 (0 without one) [1/m]
    curvature_1pm: float = 0.0  # the curvature asked for: the terms' sum, moved no further than the jerk bound allows
    # [1/m]


class LaneKeeping(Controller):
    """Curvature feed-forward plus offset/heading feedback; the gain is a time constant [s]."""

    def __init__(self, time_constant_s: float = 0.8, min_speed_mps: float = 3.0):
        """time_constant_s: T = 1/w of the lateral error [s]; min_speed_mps: the speed the gains assume below it
        [m/s], since they grow as 1/v and 1/v^2 towards a standstill."""
        if time_constant_s <= 0:
            raise ValueError(f"time_constant_s must be positive, got {time_constant_s}")
        self.T = time_constant_s
        self.v_min = min_speed_mps
        self.reset()

    def reset(self) -> None:
        self._kappa: float | None = None  # the curvature asked for on the last frame [1/m]

    def update(self, path: EgoPath, ref: LateralRef | None = None,
               dt_s: float | None = None) -> tuple[float, LaneKeepingDebug]:
        """Front-wheel angle [rad], ISO 8855 (positive turns left), and how it was made; ``ref``: where across the
        lane to hold the car (None: its centre); ``dt_s``: the time since the last call [s], which a reference's jerk
        bound needs (None: no bound)."""
        if path.lane is None:
            self._kappa = None
            return 0.0, LaneKeepingDebug(0.0, 0.0, 0.0, 0.0, "path")
        lane = path.lane
        r = ref or LateralRef(0.0, 0.0, 0.0)
        v = max(path.speed_mps, self.v_min)
        w = 1.0 / self.T
        # path heading relative to the lane: body heading plus the sideslip of the steady turn
        theta = lane.heading_rad + sideslip_for_curvature(lane.curvature_1pm)
        k_heading = 2 * w * (v * math.sin(theta) - r.rate_mps) / (v * v)
        k_offset = w * w * (lane.offset_m - r.offset_m) / (v * v)
        k_ref = r.accel_mps2 / (v * v)
        # kappa_cmd = kappa_lane + (r'' - 2 w (v sin(theta) - r') - w^2 (y - r)) / v^2
        kappa = lane.curvature_1pm + k_ref - k_heading - k_offset
        limited = "none"
        if r.max_jerk_mps3 is not None and dt_s is not None and self._kappa is not None:
            # |kappa - kappa_prev| <= j_max dt / v^2
            step = r.max_jerk_mps3 * dt_s / (v * v)
            bounded = min(max(kappa, self._kappa - step), self._kappa + step)
            limited, kappa = ("jerk" if bounded != kappa else "none"), bounded
        self._kappa = kappa
        steer = steering_for_curvature(kappa)
        limited = "steer_limit" if not STEER_RANGE_RAD[0] <= steer <= STEER_RANGE_RAD[1] else limited
        return steer, LaneKeepingDebug(lane.curvature_1pm, -k_offset, -k_heading, steer, limited, k_ref, kappa)
