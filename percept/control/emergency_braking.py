"""Emergency braking (AEB) with pedestrian yielding: the last word on the longitudinal command.

Takes the following law's command and lowers it where stopping demands: the constant deceleration that stops
short of a person, a = -v^2 / (2 s) over the room s left; an emergency brake when the deceleration needed to
cancel the closing speed before the margin, a_req = closing^2 / (2 s), exceeds a trigger (braking 30 % harder
than needed); a hold at standstill. Yielding to a pedestrian is a commitment: the car stops before their line
and goes once stopped and clear, or at once when the pedestrian slot withdraws its request (what it asked to stop
for has turned out to be no person). The comfort and braking limits clip the result.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from percept.sensors.conflict import PERSON_STOP_MARGIN_M
from percept.sensors.frame import FRAME_RATE_HZ
from percept.sensors.vehicle import MAX_BRAKE_MPS2

from .base import Controller, limiting
from .target import Target
from .tuning import STANDING_MPS, STANDSTILL_GAP_M, STOP_GAIN

MAX_ACCEL_MPS2 = 2.5
"""Comfort limit on the commanded acceleration [m/s²]."""


@dataclass(frozen=True)
class EmergencyBrakingDebug:
    """How the emergency-braking law made its command."""

    terms: dict  # every active term by name (follow, yield, emergency, hold, commitment) [m/s²]
    limited_by: str  # the term that set the command, or "brake_limit" / "accel_limit" when a limit clipped it
    stop_in_m: float | None  # distance left to a committed stop [m] (None without one)
    command_mps2: float  # the final command [m/s²]


class EmergencyBraking(Controller):
    """Acceleration [m/s²]: the following law's command, lowered where a stop or an emergency demands."""

    def __init__(self, standstill_m: float = STANDSTILL_GAP_M, ped_margin_m: float = PERSON_STOP_MARGIN_M,
                 trigger_mps2: float = 2.0, gain: float = STOP_GAIN):
        """standstill_m: margin kept to a vehicle [m]; ped_margin_m: margin kept to a pedestrian [m]; trigger_mps2:
        the required deceleration that triggers an emergency brake [m/s²]; gain: braking over the required."""
        self.d0, self.ped_margin, self.trigger, self.gain = standstill_m, ped_margin_m, trigger_mps2, gain
        self.reset()

    def reset(self) -> None:
        self.travelled_m = 0.0  # odometer: distance driven since the reset [m]
        self.stop_at_m: float | None = None  # odometer reading to stop at while yielding to a pedestrian

    def update(self, target: Target | None, speed_mps: float, follow_mps2: float, dt: float = 1.0 / FRAME_RATE_HZ,
               withdrawn: bool = False) -> tuple[float, EmergencyBrakingDebug]:
        """The command [m/s²] and its debug record. target: the nearest target (None: nothing ahead); speed_mps:
        the ego's speed; follow_mps2: the following law's command; dt: the frame period [s]; withdrawn: the
        pedestrian slot has withdrawn its request this frame (releases a commitment)."""
        v = speed_mps
        self.travelled_m += v * dt
        if withdrawn:
            self.stop_at_m = None
        self._commit(target, v)
        terms: dict[str, float | None] = {"follow": follow_mps2}
        if target is not None:
            margin = self.ped_margin if target.is_pedestrian else self.d0
            room = target.gap_m - margin
            if target.is_pedestrian:
                # yield: a constant deceleration that stops the car the margin before the person, a = -v^2 / (2 s)
                terms["yield"] = -v * v / (2 * max(room, 0.1))
            if target.closing_mps > 0:
                # emergency: the deceleration needed to cancel the closing before the margin, a = c^2 / (2 s)
                a_req = target.closing_mps * target.closing_mps / (2 * max(room, 0.1))
                if a_req > self.trigger:
                    terms["emergency"] = -self.gain * a_req
            if room < 0.5 and v < STANDING_MPS:
                terms["hold"] = -MAX_BRAKE_MPS2  # hold the car at a standstill
        stop_in = None if self.stop_at_m is None else self.stop_at_m - self.travelled_m
        if stop_in is not None:
            # a = -v^2 / (2 s) stops the car in the remaining distance s
            terms["commitment"] = -MAX_BRAKE_MPS2 if stop_in < 0.2 else -v * v / (2 * stop_in)
        a, name = limiting(terms)
        if v <= 0.05:
            # standing: a braking term weaker than 1e-3 m/s² (round-off) counts as none
            a = max(a, 0.0) if a > -1e-3 else a
        out = float(np.clip(a, -MAX_BRAKE_MPS2, MAX_ACCEL_MPS2))
        if out != a:
            name = "brake_limit" if out > a else "accel_limit"
        return out, EmergencyBrakingDebug(terms, name, stop_in, out)

    def _commit(self, target: Target | None, v: float) -> None:
        """Commit to stop before a pedestrian; release once stopped with no pedestrian ahead."""
        if target is not None and target.is_pedestrian:
            stop_at = self.travelled_m + target.gap_m - self.ped_margin
            self.stop_at_m = stop_at if self.stop_at_m is None else min(self.stop_at_m, stop_at)
        elif self.stop_at_m is not None and v < 0.3:
            self.stop_at_m = None
