"""Lane keeping: steering from lateral offset, heading and curvature (shared by privileged and vision slots).

Lateral error dynamics of a path-following car: y' = v sin(theta), theta' = v (kappa_cmd - kappa_lane).
Choosing kappa_cmd = kappa_lane - 2 w sin(theta) / v - w^2 y / v^2 gives y'' + 2 w y' + w^2 y = 0:
critically damped with time constant T = 1/w (Rajamani, *Vehicle Dynamics and Control*, 2nd ed., ch. 3).
"""

from __future__ import annotations

import math

from .base import Controller, sideslip_for_curvature, steering_for_curvature


class LaneKeeping(Controller):
    """Curvature feed-forward plus offset/heading feedback; the gain is a time constant [s]."""

    def __init__(self, time_constant_s: float = 0.8, min_speed_mps: float = 3.0):
        if time_constant_s <= 0:
            raise ValueError(f"time_constant_s must be positive, got {time_constant_s}")
        self.T = time_constant_s
        self.v_min = min_speed_mps

    def update(self, offset_m: float, heading_rad: float, curvature_1pm: float, speed_mps: float) -> float:
        """Front-wheel angle [rad], ISO 8855 (positive turns left)."""
        v = max(speed_mps, self.v_min)
        w = 1.0 / self.T
        # path heading relative to the lane: body heading plus the sideslip of the steady turn
        theta = heading_rad + sideslip_for_curvature(curvature_1pm)
        kappa = curvature_1pm - 2 * w * math.sin(theta) / v - w * w * offset_m / (v * v)
        return steering_for_curvature(kappa)
