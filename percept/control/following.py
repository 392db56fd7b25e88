"""Following (ACC): cruise at the set speed, or keep a constant time gap to what is ahead.

Gap error e = gap - gap*, gap* = max(d0, v_lead h) behind a vehicle (h the time gap), d0 behind anything else;
the law a = e / Td^2 - 2 closing / Td makes the gap error critically damped with time constant Td (constant
time-gap policy: Rajamani, *Vehicle Dynamics and Control*, 2nd ed., ch. 6). The gap aimed at is the lead's
speed times h (the same as the ego's once they match): referred to the ego's own speed it would move with every
correction (de/dt = -closing - h a), which turns the critically damped loop into an overdamped one about twice
as slow. Cruise: a = (v_set - v) / Tv.
Towards something standing still the law brakes no harder than stopping needs: at most ``gain`` times the
constant deceleration a_req = closing^2 / (2 (gap - d0)) that stops the car d0 short of it (the damped law
alone brakes hard early and then eases off).
"""

from __future__ import annotations

from dataclasses import dataclass

from percept.sensors import ObjectKind

from .base import Controller, limiting
from .target import Target
from .tuning import STANDING_MPS, STANDSTILL_GAP_M, STOP_GAIN


@dataclass(frozen=True)
class FollowingDebug:
    """How the following law made its command."""

    cruise_mps2: float  # the cruise term [m/s²]
    follow_mps2: float | None  # the gap term [m/s²] (None without a target)
    target_gap_m: float | None  # the gap aimed at [m] (None without a target)
    limited_by: str  # the term that set the command: "cruise" or "follow"
    stop_cap_mps2: float | None = None  # the bound on braking towards a standing target [m/s²] (None: not active)


class Following(Controller):
    """Acceleration [m/s²] from the set speed and the in-path target; gains as time constants [s]."""

    def __init__(self, set_speed_mps: float, time_gap_s: float = 1.8, standstill_m: float = STANDSTILL_GAP_M,
                 gap_time_constant_s: float = 2.5, speed_time_constant_s: float = 2.5, stop_gain: float = STOP_GAIN,
                 standing_mps: float = STANDING_MPS):
        """set_speed_mps: the cruise speed [m/s]; time_gap_s: h, the time gap kept to a lead vehicle [s];
        standstill_m: d0, the gap kept at a standstill [m]; gap_time_constant_s: Td [s]; speed_time_constant_s: Tv
        [s]; stop_gain: braking towards a standing target over the constant deceleration stopping needs;
        standing_mps: a target slower than this stands still [m/s]. ValueError on a non-positive time or a
        negative set speed."""
        for name, v in (("time_gap_s", time_gap_s), ("gap_time_constant_s", gap_time_constant_s),
                        ("speed_time_constant_s", speed_time_constant_s)):
            if not v > 0:
                raise ValueError(f"{name} must be positive, got {v}")
        if not set_speed_mps >= 0:
            raise ValueError(f"set_speed_mps must be >= 0, got {set_speed_mps}")
        self.set_speed, self.time_gap, self.d0 = set_speed_mps, time_gap_s, standstill_m
        self.Td, self.Tv = gap_time_constant_s, speed_time_constant_s
        self.stop_gain, self.standing_mps = stop_gain, standing_mps

    def update(self, target: Target | None, speed_mps: float) -> tuple[float, FollowingDebug]:
        """The command [m/s²] and its debug record; target: the nearest target (None: cruise), speed_mps: the ego's."""
        v = speed_mps
        # cruise: first-order approach to the set speed
        cruise = (self.set_speed - v) / self.Tv
        if target is None:
            return cruise, FollowingDebug(cruise, None, None, "cruise")
        # gap* = max(d0, h v_lead), v_lead = v - closing
        lead_speed = max(v - target.closing_mps, 0.0)
        gap_ref = max(self.d0, lead_speed * self.time_gap) if target.kind is ObjectKind.VEHICLE else self.d0
        # gap dynamics critically damped: a = (gap - gap*) / Td^2 - 2 closing / Td
        follow = (target.gap_m - gap_ref) / self.Td ** 2 - 2 * target.closing_mps / self.Td
        cap = None
        closing, room = target.closing_mps, target.gap_m - self.d0
        if closing > 0 and room > 0 and v - closing < self.standing_mps:
            # standing target: no harder than gain * a_req, a_req = closing^2 / (2 (gap - d0))
            cap = -self.stop_gain * closing * closing / (2 * room)
            follow = max(follow, cap)
        a, name = limiting({"cruise": cruise, "follow": follow})
        return a, FollowingDebug(cruise, follow, gap_ref, name, cap)
