"""Privileged implementations of the task slots: they read ground truth. Baselines for the vision modules.

Lateral: lane centring (percept.control.LaneKeeping) on the true lane. Longitudinal: constant time-gap
following (ACC) under a set speed, and emergency braking (AEB) for vehicles and for pedestrians in or
entering the ego's path.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from percept.control import Controller, LaneKeeping

EGO_HALF_LENGTH_M = 2.5
EGO_HALF_WIDTH_M = 1.0


class PrivilegedLateral(Controller):
    """Steering from the true lane geometry."""

    def __init__(self, time_constant_s: float = 0.8):
        self.law = LaneKeeping(time_constant_s)

    def update(self, lane, speed_mps: float) -> float:
        return self.law.update(lane.offset_m, lane.heading_rad, lane.curvature_1pm, speed_mps)


@dataclass(frozen=True)
class Obstacle:
    """The nearest thing in the ego's path: gap_m bumper to object [m]; speed_mps along the ego's x; kind."""

    gap_m: float
    speed_mps: float
    kind: str


def in_path_obstacle(gt, horizon_s: float = 4.0) -> Obstacle | None:
    """Nearest vehicle or pedestrian in the ego lane's corridor ahead (pedestrians also if they will enter it)."""
    lane = gt.lane
    best = None
    cam_x = 0.8  # objects' distance_m is measured from the camera, mount_x ahead of the centre
    for o in gt.objects:
        if o.kind == "landmark":
            continue
        x, y = o.position_m[0], o.position_m[1]
        if x <= 0:
            continue
        # lane centre in the vehicle frame at distance x: y_c = -offset - heading x + kappa x^2 / 2
        yc = -lane.offset_m - math.tan(lane.heading_rad) * x + lane.curvature_1pm * x * x / 2
        half = EGO_HALF_WIDTH_M + 0.4 + (o.size_m[1] / 2 if o.kind == "vehicle" else 0.3)
        vx = o.speed_mps * math.cos(o.yaw_rad)
        vy = o.speed_mps * math.sin(o.yaw_rad)
        inside = abs(y - yc) < half
        if o.kind == "pedestrian" and not inside and abs(vy) > 0.2:
            # a person walking across the carriageway: yield while within a lane of our corridor (either way),
            # or if they will step into it before the ego gets there (or within the horizon)
            t = min(horizon_s, x / max(gt.speed_mps, 1.0))
            y_future = y + vy * t
            inside = (abs(y - yc) < half + lane.width_m or abs(y_future - yc) < half
                      or (y - yc) * (y_future - yc) < 0)
        if not inside:
            continue
        gap = max(o.distance_m - (EGO_HALF_LENGTH_M - cam_x), 0.0)
        if best is None or gap < best.gap_m:
            best = Obstacle(gap, vx, o.kind)
    return best


class PrivilegedLongitudinal(Controller):
    """Acceleration [m/s^2] from the true in-path obstacle: ACC with time gap, AEB below a time to collision."""

    def __init__(self, set_speed_mps: float, time_gap_s: float = 1.8, standstill_m: float = 4.0,
                 gap_time_constant_s: float = 2.5, speed_time_constant_s: float = 2.5, ped_margin_m: float = 4.0):
        if time_gap_s <= 0:
            raise ValueError(f"time_gap_s must be positive, got {time_gap_s}")
        self.set_speed, self.time_gap, self.d0 = set_speed_mps, time_gap_s, standstill_m
        self.Td, self.Tv, self.ped_margin = gap_time_constant_s, speed_time_constant_s, ped_margin_m
        self.reset()

    def reset(self) -> None:
        self.travelled_m = 0.0
        self.stop_at_m: float | None = None  # odometer reading to stop at while yielding to a pedestrian

    def update(self, obstacle: Obstacle | None, speed_mps: float, dt: float = 1.0 / 15) -> float:
        v = speed_mps
        self.travelled_m += v * dt
        # yielding to a crossing pedestrian is a commitment: stop before their line, go once stopped and clear
        if obstacle is not None and obstacle.kind == "pedestrian":
            stop_at = self.travelled_m + obstacle.gap_m - self.ped_margin
            self.stop_at_m = stop_at if self.stop_at_m is None else min(self.stop_at_m, stop_at)
        elif self.stop_at_m is not None and v < 0.3:
            self.stop_at_m = None
        # cruise: first-order approach to the set speed
        a = (self.set_speed - v) / self.Tv
        if obstacle is not None:
            margin = self.ped_margin if obstacle.kind == "pedestrian" else self.d0
            target_gap = max(self.d0, v * self.time_gap) if obstacle.kind == "vehicle" else margin
            closing = v - obstacle.speed_mps
            # gap dynamics critically damped: a = (gap - gap*) / Td^2 - 2 closing / Td
            a_follow = (obstacle.gap_m - target_gap) / self.Td ** 2 - 2 * closing / self.Td
            if obstacle.kind == "pedestrian":
                # yield: a constant deceleration that stops the car ped_margin before the person, a = -v^2 / (2 room)
                room = max(obstacle.gap_m - margin, 0.1)
                a_follow = min(a_follow, -v * v / (2 * room))
            a = min(a, a_follow)
            # emergency: the deceleration needed to stop the closing before the margin
            room = obstacle.gap_m - margin
            if closing > 0:
                a_req = closing * closing / (2 * max(room, 0.1))
                if a_req > 2.0:
                    a = min(a, -1.3 * a_req)
            if room < 0.5 and v < 1.0:
                a = min(a, -8.0)  # hold the car at a standstill
        if self.stop_at_m is not None:
            # a = -v^2 / (2 s) stops the car in the remaining distance s
            room = self.stop_at_m - self.travelled_m
            a = min(a, -8.0 if room < 0.2 else -v * v / (2 * room))
        if v <= 0.05:
            a = max(a, 0.0) if a > -1e-3 else a
        return float(np.clip(a, -8.0, 2.5))
