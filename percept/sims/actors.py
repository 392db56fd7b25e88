"""Actors that highway-env does not have: walking pedestrians, mapped signs, scripted vehicles and lane ends.

All are highway-env road objects, so its collision handling and its IDM traffic see them.
Positions and headings here are highway-env's (y to the right); sims/coords.py converts them.
"""

from __future__ import annotations

import numpy as np
from highway_env.vehicle.behavior import IDMVehicle
from highway_env.vehicle.objects import Landmark, Obstacle, RoadObject


class Pedestrian(RoadObject):
    """A person on foot: walks from its start along ``direction`` at ``walk_speed_mps`` once triggered.

    trigger_x_m: the walk starts when the ego's highway-env x passes this value (None: walks from the
    start, or never if ``walk_speed_mps`` is 0); walk_distance_m: it stops after this distance.
    crossing: True for people who cross the road (the ego must stop for them), False for roadside ones.
    """

    LENGTH = 0.45
    WIDTH = 0.6

    def __init__(self, road, position, heading: float = 0.0, *, height_m: float = 1.75, style: int = 0,
                 walk_speed_mps: float = 0.0, walk_distance_m: float = np.inf, trigger_x_m: float | None = None,
                 crossing: bool = False):
        super().__init__(road, position, heading, 0.0)
        self.height_m = height_m
        self.style = style
        self.walk_speed_mps = walk_speed_mps
        self.walk_distance_m = walk_distance_m
        self.trigger_x_m = trigger_x_m
        self.crossing = crossing
        self.walked_m = 0.0
        self.gait_phase = float(style % 7)
        self.started = trigger_x_m is None and walk_speed_mps > 0
        self.check_collisions = False  # vehicles check against it

    def update(self, dt: float, ego_x_hw: float) -> None:
        """Advance the walk by dt [s]."""
        if not self.started and self.trigger_x_m is not None and ego_x_hw >= self.trigger_x_m:
            self.started = True
        if self.crashed or not self.started or self.walked_m >= self.walk_distance_m:
            self.speed = 0.0
            return
        self.speed = self.walk_speed_mps
        step = min(self.walk_speed_mps * dt, self.walk_distance_m - self.walked_m)
        self.position = self.position + step * self.direction
        self.walked_m += step
        # gait: one stride (two steps) per ~1.4 m at normal speed: phase rate = 2 pi v / stride
        stride_m = 0.8 * self.height_m
        self.gait_phase = (self.gait_phase + 2 * np.pi * step / stride_m) % (2 * np.pi)


class Sign(Landmark):
    """A roadside landmark sign with a unique ArUco face; not solid (cars cannot hit it: it is off the road)."""

    LENGTH = 0.1
    WIDTH = 0.9

    def __init__(self, road, position, heading: float, marker_id: int):
        super().__init__(road, position, heading, 0.0)
        self.marker_id = int(marker_id)
        self.collidable = False


class LaneEnd(Obstacle):
    """Where a lane ends (an acceleration lane's end): highway-env's Obstacle, which its IDM traffic brakes for and
    its MOBIL lane changes leave, as in highway-env's merge-v0. Nothing is drawn there: the lane's markings end."""


PACE_TIME_CONSTANT_S = 1.0
"""How fast a pacing vehicle settles on its place beside the ego: critically damped with this time constant [s]."""


class ScriptedVehicle(IDMVehicle):
    """IDM traffic with one scripted event.

    brake_at_s: from this time on it brakes at ``brake_mps2`` (< 0) to a standstill (``lead-brake``);
    cut_in_lane: when its gap ahead of the ego in x is within ``cut_in_gap_m`` it changes to this lane index;
    merge_road: (from, to) nodes of the road (an acceleration lane's) on which its MOBIL lane changes switch on,
    and stay on (a ramp vehicle that may not cross the gore before it);
    pace_offset_m: once its x minus the ego's [m] reaches this value it holds it (beside the ego) for ``pace_s``
    seconds, matching the ego's speed (never faster than IDM allows behind a car ahead), then drives on as IDM
    traffic.
    The scenario calls ``script(time_s, ego)`` every simulation step.
    """

    def __init__(self, *args, brake_at_s: float | None = None, brake_mps2: float = -6.0,
                 cut_in_lane=None, cut_in_gap_m: float = 15.0, merge_road: tuple[str, str] | None = None,
                 pace_offset_m: float | None = None, pace_s: float = 0.0, **kwargs):
        super().__init__(*args, **kwargs)
        self.brake_at_s = brake_at_s
        self.brake_mps2 = brake_mps2
        self.cut_in_lane = cut_in_lane
        self.cut_in_gap_m = cut_in_gap_m
        self.merge_road = merge_road
        self.pace_offset_m, self.pace_s = pace_offset_m, pace_s
        self.pace_from_s: float | None = None  # when the pacing began [s] (None: not yet)
        self.pace_mps2: float | None = None  # the pacing command of this step [m/s²] (None: IDM drives)
        self.braking = False
        self.cut_in_done = False
        self.enable_lane_change = False

    def script(self, time_s: float, ego) -> None:
        if self.brake_at_s is not None and time_s >= self.brake_at_s:
            self.braking = True
        if self.cut_in_lane is not None and not self.cut_in_done:
            gap = self.position[0] - ego.position[0] - self.LENGTH
            if gap <= self.cut_in_gap_m:
                self.target_lane_index = self.cut_in_lane
                self.cut_in_done = True
        if self.merge_road is not None and self.lane_index[:2] == self.merge_road:
            self.enable_lane_change = True
        if self.pace_offset_m is not None:
            self._pace(time_s, ego)

    def _pace(self, time_s: float, ego) -> None:
        """Hold x - x_ego at ``pace_offset_m`` for ``pace_s`` seconds from when it is first reached."""
        dx = self.position[0] - ego.position[0]
        if self.pace_from_s is None and dx >= self.pace_offset_m:
            self.pace_from_s = time_s
        if self.pace_from_s is None or time_s > self.pace_from_s + self.pace_s:
            self.pace_mps2 = None
            return
        T = PACE_TIME_CONSTANT_S
        # critically damped on the offset: a = (x* - dx) / T^2 + 2 (v_ego - v) / T
        self.pace_mps2 = (self.pace_offset_m - dx) / T ** 2 + 2 * (float(ego.speed) - self.speed) / T

    def act(self, action=None):
        super().act(action)
        if self.braking:
            # brake at a constant deceleration to a standstill
            self.action["acceleration"] = self.brake_mps2
        elif self.pace_mps2 is not None:
            # pacing, but never faster than IDM allows behind whoever is ahead in its lane
            pace = float(np.clip(self.pace_mps2, -self.ACC_MAX, self.ACC_MAX))
            self.action["acceleration"] = min(pace, float(self.action["acceleration"]))

    def step(self, dt: float) -> None:
        super().step(dt)
        # brakes stop the car, they do not drive it backwards
        if self.speed < 0.0:
            self.speed = 0.0
