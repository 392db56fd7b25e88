"""Lane changes: when MOBIL favours a lane beside (``mobil.judge``), a minimum-jerk path into it that lane keeping
follows, and a return to the lane it left when the target gap closes before the car is across; and the swerve into a
free lane that the evasion law (``evasion.py``) calls for when braking alone falls short.

The law reads records only: the ego path (its lane, the lane's ``index`` and which boundaries have a lane beyond
them) and the neighbours. A change starts once MOBIL has favoured the same side for ``settle_s`` (a verdict that
flickers with perception's noise starts nothing) and ``min_interval_s`` after the last one ended, and never into a
lane that opened beside the car less than ``new_lane_m`` back (an acceleration lane's end is not marked before it
comes). The path is planned in the frame of the lane the change started from; the lane estimate moves to the target
lane as the car's centre crosses the boundary (its ``index`` changes), and the reference moves with it: offset in
the current lane = offset in the start lane - (index - index_start) w. A change goes back while a gentle return
(within the lane, within the jerk bound) exists; past that point, about a second in, going back is harsher than going
on, so it goes on unless the target lane turns unsafe by looser bounds (a car beside, a gap under half a second, the
new follower braking harder than 3 m/s²).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field, replace
from enum import Enum

import numpy as np

from percept.sensors import EgoPath, Neighbours

from .base import Controller
from .evasion import Evasion, EvasionConfig, EvasionDebug
from .lateral_path import LateralRef, MinJerkPath
from .mobil import Judgement, MobilConfig, judge
from .target import Target

PLAN_POINTS = 12
"""Points of the rest of the path in the debug record (the review draws them)."""


class Phase(str, Enum):
    """What the law is doing."""

    KEEP = "keep"  # keeping the lane
    CHANGE = "change"  # on the path into the lane beside
    RETURN = "return"  # on the path back into the lane it left (an aborted change)
    EVADE = "evade"  # on a swerve into a free lane beside (evasion.py), which nothing aborts


@dataclass(frozen=True)
class LaneChangeConfig:
    """When to change lanes and how."""

    duration_s: float = 5.0  # T: how long a change takes, and a return at least [s]
    return_jerk_mps3: float = 2.0  # a gentle return's path asks at most this peak jerk (a 4 m change from rest in
    # 5 s asks 1.92); lane keeping adds its own on top [m/s³]
    return_max_s: float = 8.0  # a return takes from the swerve's time (evasion.duration_s) up to this long [s]
    return_margin_m: float = 0.3  # ... and keeps the car's centre this far inside the boundary of the lane it left
    # (a longer return turns back later) [m]
    max_jerk_mps3: float = 2.5  # the most lateral jerk lane keeping may command on a change's path or a gentle
    # return's, its corrections included (the path itself asks up to return_jerk_mps3); a swerve and a harsh return
    # are not bounded [m/s³]
    commit_gap_s: float = 0.5  # past the point where a gentle return exists, a change goes on unless a gap in the
    # target lane is under this at the ego's speed ... [s]
    commit_braking_mps2: float = 3.0  # ... or the new follower would brake harder than this, or a car is beside
    # [m/s²]
    settle_s: float = 1.0  # how long MOBIL must favour the same side before a change starts [s]
    min_interval_s: float = 8.0  # least time from the end of one change to the start of the next [s]
    unseen_window_s: float = 10.0  # with no follower in view in the target lane, one is assumed at the rear view's
    # edge going the fastest the ego went in this long (traffic the ego braked out of, closing fast from beyond the
    # view) [s]
    new_lane_m: float = 500.0  # a lane that opened beside the car (its boundary was the road's edge, a solid line)
    # less than this far back may be an acceleration lane, whose end is not marked: no change goes into it [m]
    mobil: MobilConfig = field(default_factory=MobilConfig)  # the decision's parameters
    evasion: EvasionConfig = field(default_factory=EvasionConfig)  # when to swerve, and how fast


@dataclass(frozen=True)
class LaneChangeDebug:
    """How the lane-change law decided this frame."""

    phase: Phase  # what it is doing
    side: int  # the side of the change under way (+1 left, -1 right; 0 none)
    reason: str  # why, in words: MOBIL's gain for the side taken, its reasons for those not taken, or "too soon",
    # "no lane estimate", "on the path", "arrived", "not across" (a path that ended short of the target lane)
    judgements: tuple[Judgement, ...]  # MOBIL's verdicts this frame
    event: str | None  # "started", "completed", "aborted", or evasion's "swerve" / "full braking", on the frame it
    # happened, else None
    ref: LateralRef | None  # the lateral reference handed to lane keeping (None: keep the lane's centre)
    plan_m: tuple = ()  # the rest of the path as (ahead [m], offset from the current lane's centre [m]) points at
    # the ego's speed (PLAN_POINTS of them; empty outside a change)
    into_lane: int = 0  # the target lane relative to the current one while the car is not yet across it (+1 left,
    # -1 right), else 0: the following law watches that lane's nearest car ahead as well
    evasion: EvasionDebug | None = None  # the evasion law's judgement (None: not judged this frame)


class LaneChange(Controller):
    """The lateral reference for lane keeping: None while keeping the lane, the path's point during a change."""

    def __init__(self, set_speed_mps: float, cfg: LaneChangeConfig = LaneChangeConfig()):
        """set_speed_mps: the speed the car wants [m/s] (MOBIL's desired speed for the ego)."""
        self.set_speed, self.cfg = set_speed_mps, cfg
        self.evasion = Evasion(set_speed_mps, cfg.evasion, cfg.mobil)
        self.reset()

    def reset(self) -> None:
        self.phase, self.side = Phase.KEEP, 0
        self.t_s = 0.0  # time on the current path [s]
        self.since_end_s = self.cfg.min_interval_s  # time since the last change ended [s]
        self.favour, self.favour_s = 0, 0.0  # the side MOBIL favours, and for how long [s]
        self.edge_index: int | None = None  # the lane index edge_ago_m was counted in
        self.edge_ago_m: dict[int, float | None] = {1: None, -1: None}  # side -> how far back its boundary was the
        # road's edge (None: not seen so since the car came into this lane) [m]
        self.path: MinJerkPath | None = None  # in the start lane's frame
        self.index0 = 0  # the lane index the change started from
        self.width0 = 0.0  # the lane width it was planned with [m]
        self.jerk_bound: float | None = None  # the jerk bound handed to lane keeping on this path [m/s³]
        self.speeds: deque[float] = deque()  # the ego's speed on each frame of the last unseen_window_s [m/s]
        self.unseen_mps = 0.0  # the fastest of them: the speed of a follower assumed beyond the rear view [m/s]
        self.evasion.reset()

    def update(self, path: EgoPath, neighbours: Neighbours | None, speed_mps: float, dt: float,
               target: Target | None = None) -> tuple[LateralRef | None, LaneChangeDebug]:
        """The reference (None: the lane's centre) and the debug record, from the ego path, the neighbours (None:
        nothing is known around the car, so no change starts; one under way goes on), the speed [m/s], the frame
        period ``dt`` [s] and the longitudinal laws' nearest target (``nearest_target`` with no change under way;
        None: nothing ahead), which evasion judges while the car keeps its lane. Without a view behind
        (``Neighbours.rear`` False) no change starts either."""
        self._watch_speeds(speed_mps, dt)
        if not path.follows_lane:  # nothing to steer along: a path under way runs on unseen
            self.favour, self.favour_s = 0, 0.0
            self.t_s += dt if self.phase is not Phase.KEEP else 0.0
            return None, LaneChangeDebug(self.phase, self.side, "no lane estimate", (), None, None)
        self._watch_edges(path.lane.index, path.lane.beside, speed_mps * dt)
        if self.phase is Phase.KEEP:
            barred = frozenset(s for s in (1, -1) if self._new_lane(s, path.lane.lane_beside(s)))
            side, evasion = self.evasion.update(target, path, neighbours, speed_mps, barred)
            if side:
                return self._start(Phase.EVADE, side, path, self.cfg.evasion.duration_s, evasion.reason, evasion)
            ref, debug = self._keep(path, neighbours, speed_mps, dt)
            return ref, replace(debug, evasion=evasion, event=debug.event or evasion.event)
        return self._follow(path, neighbours, speed_mps, dt)

    def _keep(self, path: EgoPath, neighbours: Neighbours | None, speed_mps: float,
              dt: float) -> tuple[LateralRef | None, LaneChangeDebug]:
        """Keeping the lane: MOBIL on both sides; a change starts on the side favoured for ``settle_s``."""
        self.since_end_s += dt
        lane = path.lane
        seen = neighbours is not None and neighbours.rear
        verdicts = tuple(self._judge(s, lane.lane_beside(s), neighbours, speed_mps) for s in (1, -1)) if seen else ()
        best = max((j for j in verdicts if j.go), key=lambda j: j.gain_mps2, default=None)
        side = best.side if best is not None else 0
        self.favour_s = self.favour_s + dt if side == self.favour and side else 0.0
        self.favour = side
        reason = (f"gain {best.gain_mps2:.2f} m/s², new follower {best.imposed_mps2:+.2f} m/s²" if best is not None
                  else _why_not(verdicts))
        if best is None or self.favour_s < self.cfg.settle_s:
            return None, LaneChangeDebug(self.phase, 0, reason, verdicts, None, None)
        if self.since_end_s < self.cfg.min_interval_s:
            return None, LaneChangeDebug(self.phase, 0, "too soon", verdicts, None, None)
        return self._start(Phase.CHANGE, side, path, self.cfg.duration_s, reason, None, verdicts)

    def _watch_speeds(self, speed_mps: float, dt: float) -> None:
        """Keep the ego's speed ``speed_mps`` [m/s] over the last ``unseen_window_s``: a car going as fast as the ego
        went lately may come from beyond the rear view into a lane the ego, slowed down, changes into."""
        self.speeds.append(speed_mps)
        while len(self.speeds) > max(round(self.cfg.unseen_window_s / dt), 1):
            self.speeds.popleft()
        self.unseen_mps = max(self.speeds)

    def _watch_edges(self, index: int, beside: tuple, moved_m: float) -> None:
        """Count how far the car has gone (``moved_m`` this frame [m]) since each boundary of lane ``index`` was
        last the road's edge (``beside``: the lane estimate's (left, right) verdicts); a new lane forgets them."""
        if index != self.edge_index:
            self.edge_index, self.edge_ago_m = index, {1: None, -1: None}
        for side, there in zip((1, -1), beside):
            ago = self.edge_ago_m[side]
            self.edge_ago_m[side] = 0.0 if there is False else None if ago is None else ago + moved_m

    def _new_lane(self, side: int, lane_there: bool | None) -> bool:
        """Whether the lane on ``side`` opened less than ``new_lane_m`` back (its boundary was the road's edge)."""
        ago = self.edge_ago_m[side]
        return bool(lane_there) and ago is not None and ago < self.cfg.new_lane_m

    def _judge(self, side: int, lane_there: bool | None, neighbours: Neighbours, speed_mps: float) -> Judgement:
        """MOBIL's verdict on ``side``, or "new lane" for a lane that opened less than ``new_lane_m`` back."""
        if self._new_lane(side, lane_there):
            return Judgement(side, 0.0, 0.0, "new lane")
        return judge(side, lane_there, neighbours, speed_mps, self.set_speed, self.cfg.mobil, self.unseen_mps)

    def _start(self, phase: Phase, side: int, path: EgoPath, duration_s: float, reason: str,
               evasion: EvasionDebug | None,
               verdicts: tuple[Judgement, ...] = ()) -> tuple[LateralRef, LaneChangeDebug]:
        """Begin a path of ``duration_s`` from where the car is into the lane on ``side``: a change or a swerve."""
        lane = path.lane
        self.phase, self.side, self.t_s, self.index0, self.width0 = phase, side, 0.0, lane.index, lane.width_m
        self.path = MinJerkPath.between(lane.offset_m, 0.0, 0.0, side * lane.width_m, duration_s)
        self.jerk_bound = self.cfg.max_jerk_mps3 if phase is Phase.CHANGE else None
        ref = replace(self.path.at(0.0), max_jerk_mps3=self.jerk_bound)
        event = "started" if evasion is None else evasion.event
        return ref, LaneChangeDebug(phase, side, reason, verdicts, event, ref, into_lane=side, evasion=evasion)

    def _follow(self, path: EgoPath, neighbours: Neighbours | None, speed_mps: float,
                dt: float) -> tuple[LateralRef | None, LaneChangeDebug]:
        """On a path: its point in the current lane's frame; a change not yet across returns when MOBIL's safety
        fails on its side; the path's end ends the manoeuvre."""
        self.t_s += dt
        crossed = path.lane.index - self.index0
        planned = self.path.at(self.t_s)
        event, verdicts, reason = None, (), "on the path"
        if self.t_s >= self.path.duration_s:
            return self._end(crossed)
        if self.phase is Phase.CHANGE and not crossed and neighbours is not None:
            verdict = judge(self.side, True, neighbours, speed_mps, self.set_speed, self.cfg.mobil, self.unseen_mps)
            verdicts, reason = (verdict,), verdict.reason
            if not verdict.safe:  # the gain may fade without ending it
                back, gentle = self._return(planned)
                if gentle or not self._loosely_safe(neighbours, speed_mps):
                    self.phase, event, self.t_s, self.path = Phase.RETURN, "aborted", 0.0, back
                    self.jerk_bound = self.cfg.max_jerk_mps3 if gentle else None
                else:
                    reason = f"committed ({verdict.reason})"
        # offset in the current lane = offset in the start lane - (index - index_start) w (the width planned with)
        shift = crossed * self.width0
        ref = LateralRef(planned.offset_m - shift, planned.rate_mps, planned.accel_mps2, self.jerk_bound)
        ahead = [self.t_s + k * (self.path.duration_s - self.t_s) / (PLAN_POINTS - 1) for k in range(PLAN_POINTS)]
        plan = tuple((speed_mps * (t - self.t_s), self.path.at(t).offset_m - shift) for t in ahead)
        into = self.side if self.phase is not Phase.RETURN and not crossed else 0
        return ref, LaneChangeDebug(self.phase, self.side, reason, verdicts, event, ref, plan, into)

    def _return(self, at: LateralRef) -> tuple[MinJerkPath, bool]:
        """The path back to the centre of the lane the change left, from ``at`` (in its frame), and whether it is
        gentle. Of the quintics from the swerve's time up to ``return_max_s`` (0.25 s apart) that keep the car's centre
        ``return_margin_m`` inside the lane: the shortest whose peak jerk is within ``return_jerk_mps3`` (gentle), else
        the one with the least jerk; when none keeps inside (the car is nearly across), the shortest."""
        c = self.cfg
        y0, v0, a0 = at.offset_m, at.rate_mps, at.accel_mps2
        durations = np.arange(c.evasion.duration_s, c.return_max_s + 1e-9, 0.25)
        paths = [MinJerkPath.between(y0, v0, a0, 0.0, float(T)) for T in durations]
        # |y| <= w/2 - margin all along the path
        inside = [p for p in paths if max(abs(y) for y in p.extent_m) <= self.width0 / 2 - c.return_margin_m]
        gentle = [p for p in inside if p.peak_jerk_mps3 <= c.return_jerk_mps3]
        if gentle:
            return gentle[0], True
        return (min(inside, key=lambda p: p.peak_jerk_mps3) if inside else paths[0]), False

    def _loosely_safe(self, neighbours: Neighbours, speed_mps: float) -> bool:
        """Whether the target lane passes MOBIL's safety test with the commitment's looser bounds (``commit_gap_s``,
        ``commit_braking_mps2``) on the estimates themselves, not shortened by their sigmas: a change past its gentle
        return goes on while it does. A harsh return is a hazard of its own, for a threat the estimates show, not one
        their uncertainty allows (a track just born 90 m behind, its speed uncertain by several m/s, had turned a
        change back at 5 m/s²)."""
        c = self.cfg
        loose = replace(c.mobil, min_time_gap_s=c.commit_gap_s, safe_braking_mps2=c.commit_braking_mps2, sigmas=0.0)
        return judge(self.side, True, neighbours, speed_mps, self.set_speed, loose).safe

    def _end(self, crossed: int) -> tuple[None, LaneChangeDebug]:
        """The path's end: a change is completed when the lane estimate has moved to the target lane, else (it never
        got across) it counts as aborted; a return just ends."""
        side, changing = self.side, self.phase is Phase.CHANGE  # a swerve ends with no event: it counts as a swerve
        event = ("completed" if crossed == side else "aborted") if changing else None
        self.phase, self.side, self.since_end_s = Phase.KEEP, 0, 0.0
        reason = "arrived" if event != "aborted" else "not across"
        return None, LaneChangeDebug(self.phase, side, reason, (), event, None)


def _why_not(verdicts: tuple[Judgement, ...]) -> str:
    """The reasons no side is taken, left's then right's."""
    return "; ".join(f"{'left' if j.side > 0 else 'right'}: {j.reason}" for j in verdicts) or "no neighbours"
