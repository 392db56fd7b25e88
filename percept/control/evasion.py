"""Evasion: when a vehicle cutting in (or the lead) is closer than braking alone can handle at the laws' limits,
swerve into a free lane beside if there is one; else it is full braking's to handle.

Braking falls short when the emergency-braking law's own demand, ``STOP_GAIN`` c² / (2 (g - margin)) for a gap g
closing at c, exceeds the strongest deceleration a law may command (``MAX_BRAKE_MPS2``): the law would be clipped at
its limit. A lane beside is free when it exists, is not barred by the lane-change law (one that opened beside the car
lately may be an acceleration lane, whose end nothing marks) and MOBIL's safety test passes there (no track beside the
ego, both gaps at least ``MobilConfig.min_time_gap_s``, the new follower braking no harder than
``safe_braking_mps2``); the side away from the vehicle cutting in is taken first. The law reads records only and
decides; the lane-change law (``lane_change.py``) flies the swerve.
"""

from __future__ import annotations

from dataclasses import dataclass

from percept.sensors import EgoPath, Neighbours, ObjectKind
from percept.sensors.vehicle import MAX_BRAKE_MPS2

from .base import Controller
from .mobil import MobilConfig, judge
from .target import Target
from .tuning import STOP_GAIN

EVASIVE_EVENTS = ("swerve", "full braking")
"""The events that begin an evasive manoeuvre (``EvasionDebug.event``)."""


@dataclass(frozen=True)
class EvasionConfig:
    """When to swerve and how fast."""

    margin_m: float = 1.0  # room kept short of the vehicle when judging whether braking cancels the closing [m]
    confirm_frames: int = 2  # frames in a row braking must fall short before the car acts (one noisy range does
    # not swerve it) [-]
    duration_s: float = 2.0  # T of the swerve's minimum-jerk path into the free lane [s]


@dataclass(frozen=True)
class EvasionDebug:
    """How the evasion law judged this frame."""

    needed_mps2: float | None  # the braking the emergency law would need, STOP_GAIN c² / (2 (g - margin)) [m/s²]
    # (None: no vehicle closing ahead)
    short_frames: int  # frames in a row braking has fallen short
    side: int  # the free lane swerved into (+1 left, -1 right; 0 none)
    reason: str  # "braking suffices", "swerve left", "swerve right" or "no free lane: full braking"
    event: str | None  # "swerve" or "full braking" on the frame an evasive manoeuvre begins, else None


class Evasion(Controller):
    """The side to swerve to (0: none) when braking alone falls short."""

    def __init__(self, set_speed_mps: float, cfg: EvasionConfig = EvasionConfig(),
                 mobil: MobilConfig = MobilConfig()):
        """set_speed_mps: the speed the car wants [m/s] (MOBIL's desired speed, for its safety test)."""
        self.set_speed, self.cfg, self.mobil = set_speed_mps, cfg, mobil
        self.reset()

    def reset(self) -> None:
        self.short = 0  # frames in a row braking has fallen short
        self.acting = False  # an evasive manoeuvre is under way (one event per episode)

    def needed(self, target: Target | None) -> float | None:
        """The deceleration [m/s²] the emergency-braking law would command for ``target`` (None: no vehicle
        closing)."""
        if target is None or target.kind is not ObjectKind.VEHICLE or target.closing_mps <= 0:
            return None
        if target.source not in ("cut-in", "lead"):
            return None
        room = max(target.gap_m - self.cfg.margin_m, 0.1)
        # a = STOP_GAIN c^2 / (2 (g - margin))
        return STOP_GAIN * target.closing_mps ** 2 / (2 * room)

    def update(self, target: Target | None, path: EgoPath, neighbours: Neighbours | None,
               speed_mps: float, barred: frozenset = frozenset()) -> tuple[int, EvasionDebug]:
        """The side to swerve to this frame (+1, -1; 0: none) and the debug record. target: the nearest target before
        any lane change (``nearest_target``); path: the ego path (which lanes exist beside); neighbours: the
        neighbours record (None, or no view behind: no lane is known free); speed_mps: the ego's speed; barred: the
        sides never swerved to (lanes that opened beside the car lately, which may be acceleration lanes whose end
        nothing marks)."""
        need = self.needed(target)
        self.short = self.short + 1 if need is not None and need > MAX_BRAKE_MPS2 else 0
        if self.short < self.cfg.confirm_frames:
            self.acting = False
            return 0, EvasionDebug(need, self.short, 0, "braking suffices", None)
        side = self._free_side(target, path, neighbours, speed_mps, barred)
        event = None if self.acting else EVASIVE_EVENTS[0 if side else 1]
        self.acting = True
        reason = f"swerve {'left' if side > 0 else 'right'}" if side else "no free lane: full braking"
        return side, EvasionDebug(need, self.short, side, reason, event)

    def _free_side(self, target: Target, path: EgoPath, neighbours: Neighbours | None, speed_mps: float,
                   barred: frozenset) -> int:
        """The free lane beside (+1, -1; 0 none) and not ``barred``, the one away from a vehicle cutting in first."""
        if neighbours is None or not neighbours.rear or not path.follows_lane:
            return 0
        cutter = neighbours.cutting_in() if target.source == "cut-in" else None
        order = (-cutter.lane, cutter.lane) if cutter is not None else (1, -1)
        for side in (s for s in order if s not in barred):
            if judge(side, path.lane.lane_beside(side), neighbours, speed_mps, self.set_speed, self.mobil).safe:
                return side
        return 0
