"""Events the neighbours scorer follows over a run: true cut-ins and the warnings for them, and who moved into whom
when the ego collides with a vehicle.

A cut-in is a true vehicle whose lane relative to the ego's goes from +-1 to 0 while it is ahead within
``CUT_IN_GAP_M``, having been clear of the ego lane (all of its width beyond the boundary) since it was last in it:
the frame its centre crosses the ego lane's boundary. A car that turns back halfway out of the ego lane never left
it. Its warning lead is the crossing time less the onset of the warning run, on a track matched to that vehicle,
still going on the frame before (0 when there is none: a missed cut-in). A warning onset is false when its track's
vehicle does not cross into the ego lane (ahead, beside or behind, at any gap) within ``FALSE_WARNING_S``; onsets
whose window outlasts the run are not judged.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

from percept.sensors import EGO_LENGTH_M, Zone
from percept.sensors.vehicle import EGO_WIDTH_M

from .neighbours_truth import ego_lane_velocity, lane_velocity, lateral_from_ego_lane

CUT_IN_GAP_M = 60.0
"""A crossing into the ego lane is a cut-in when the vehicle is ahead within this bumper gap [m]."""
FALSE_WARNING_S = 3.0
"""A warning is justified when its vehicle crosses into the ego lane within this after its onset, or while the warning
goes on (a merging car may wait on the line) [s]."""
SEEN_BEFORE_S = 2.0
"""A cut-in's warning lead is scored when a rig had seen its car at least this long before it crossed; one that
crossed sooner after it came into view (a car already moving over as the run begins) is counted apart, in
``cut_ins_unscored`` [s]."""
CROSSED_FIRST_S = 1.0
"""The estimate and the truth may see a car cross into the ego lane up to this far apart: a warning run goes on for up
to this long after its track has crossed in the estimate (the flag ends there: the car is now a lead) while the true
car has not yet, and a warning begun up to this long after its car crossed in truth is late, not false [s]."""
COLLISION_WINDOW_S = 1.0
"""Lateral speeds before a collision are averaged over this [s]."""
LATERAL_MOVE_MPS = 0.3
"""Moving sideways towards the other faster than this makes a vehicle the mover in a collision [m/s]."""


@dataclass
class _Onset:
    """A warning run's first frame, waiting for its vehicle to cross (or not) within FALSE_WARNING_S."""

    time_s: float  # its first frame [s]
    track_id: int  # the warning track
    vehicle_id: int | None  # the true vehicle matched to the track (None until one is)


class CutInEvents:
    """True crossings into the ego lane and, when ``scored``, the warning lead of each and the false warnings."""

    def __init__(self, scored: bool):
        self.scored = scored
        self.leads_s: list[float] = []  # per crossing, its warning lead [s] (0: missed), when scored
        self.crossings = 0
        self.missed = 0
        self.false_warnings = 0
        self._lanes: dict = {}  # vehicle id -> its relative lane on the previous frame
        self._lane_id = None  # the ego's lane id on the previous frame
        self._since: dict = {}  # track id -> onset of its warning run going on at the previous frame [s]
        self._matched: dict = {}  # track id -> vehicle id, on the previous frame
        self._pending: list[_Onset] = []
        self._last_s = 0.0  # the last frame's time [s]
        self._first_seen: dict = {}  # vehicle id -> when a rig first saw it at least half [s]
        self.unscored = 0  # cut-ins whose car crossed less than SEEN_BEFORE_S after a rig first saw it
        self._clear: set = set()  # vehicles clear of the ego lane since they were last in it
        self._in_lane: dict = {}  # track id -> when its warning run's track came into the ego lane (estimate) [s]
        self._entered_s: dict = {}  # vehicle id -> when it last moved into the ego lane (truth) [s]

    def update(self, gt, truth: dict, tracks, matched: dict) -> None:
        """One frame of ground truth ``gt``: ``truth`` vehicle id -> its true ``Neighbour``; ``tracks`` the estimated
        ``Neighbour``s; ``matched`` track id -> vehicle id. When the ego's own lane changes (the lane id of its lane
        index; the road's segment changes at every node), the relative lanes jump: no crossing."""
        time_s = gt.time_s
        # into the ego lane anywhere (a warning for any of them is justified); ahead within CUT_IN_GAP_M: cut-ins
        lane_id = gt.lane.lane_index[-1]
        entered = [] if lane_id != self._lane_id else [
            v for v, n in truth.items() if n.lane == 0 and self._lanes.get(v) in (-1, 1)]
        crossed = [v for v in entered if truth[v].zone is Zone.AHEAD and truth[v].gap_m <= CUT_IN_GAP_M
                   and v in self._clear]
        self._follow_clear(gt, truth)
        self.crossings += len(crossed)
        self._entered_s.update((v, time_s) for v in entered)
        for v, n in truth.items():
            if n.camera is not None:
                self._first_seen.setdefault(v, time_s)
        if self.scored:
            for v in crossed:
                if time_s - self._first_seen.get(v, time_s) < SEEN_BEFORE_S:
                    self.unscored += 1
                    continue
                self._score_crossing(time_s, v, matched)
            self._follow_warnings(time_s, tracks, matched)
        self._lanes = {v: n.lane for v, n in truth.items()}
        self._lane_id = lane_id
        self._matched = dict(matched)

    def _follow_clear(self, gt, truth: dict) -> None:
        """Which vehicles are clear of the ego lane since they were last in it (all of their width beyond it)."""
        w = gt.lane.width_m
        car_width = {o.obj_id: float(o.size_m[1]) for o in gt.objects}
        for v, n in truth.items():
            # clear: |l_ego| >= w/2 + W/2, l_ego = lane w + l its offset from the ego lane's centre line
            if abs(n.lane * w + n.lateral_m) >= (w + car_width[v]) / 2:
                self._clear.add(v)
            elif n.lane == 0:
                self._clear.discard(v)

    def _score_crossing(self, time_s: float, vehicle_id, matched: dict) -> None:
        """The lead of the warning run on a track matched to ``vehicle_id`` (now or the frame before)."""
        tracks = {t for t, v in self._matched.items() if v == vehicle_id} | {t for t, v in matched.items()
                                                                              if v == vehicle_id}
        onsets = [self._since[t] for t in tracks if t in self._since]
        # lead = t_cross - t_onset of the run still on the frame before the crossing
        lead = time_s - min(onsets) if onsets else 0.0
        self.leads_s.append(lead)
        self.missed += int(not onsets)

    def _follow_warnings(self, time_s: float, tracks, matched: dict) -> None:
        """Onsets of warning runs, and the judgement of each FALSE_WARNING_S after it. A run goes on while its track
        is flagged, and for CROSSED_FIRST_S once its track is in the ego lane (the estimate may see the car cross a
        frame or two before the truth does). A run is justified when its vehicle moves into the ego lane while it is
        judged, or had done so at most CROSSED_FIRST_S before its onset (a late warning, not a false one)."""
        warning = {n.track_id for n in tracks if n.cut_in}
        # runs whose track the estimate already has in the ego lane: since when
        crossed = ({n.track_id for n in tracks if n.lane == 0} & self._since.keys()) - warning
        self._in_lane = {t: self._in_lane.get(t, time_s) for t in crossed}
        warning |= {t for t, s in self._in_lane.items() if time_s - s <= CROSSED_FIRST_S}
        for t in sorted(warning - self._since.keys()):
            self._since[t] = time_s
            self._pending.append(_Onset(time_s, t, matched.get(t)))
        self._since = {t: s for t, s in self._since.items() if t in warning}
        keep = []
        for o in self._pending:
            o.vehicle_id = matched.get(o.track_id) if o.vehicle_id is None else o.vehicle_id
            if self._entered_s.get(o.vehicle_id, -math.inf) >= o.time_s - CROSSED_FIRST_S:
                continue  # justified: its vehicle moved into the ego lane within the window or the warning, or late
            if time_s - o.time_s > FALSE_WARNING_S and o.track_id not in warning:
                self.false_warnings += 1
            else:
                keep.append(o)
        self._pending = keep
        self._last_s = time_s

    def result(self, minutes: float | None) -> dict:
        """The group's cut-in keys; ``minutes``: the run's length [min] (None: too short to rate)."""
        s = self.scored
        # warnings still going on at the end, older than the window, whose vehicle never crossed
        unjustified = sum(self._last_s - o.time_s > FALSE_WARNING_S for o in self._pending)
        return {"cut_ins": self.crossings,
                "cut_ins_missed": self.missed if s else None,
                "cut_ins_unscored": self.unscored if s else None,
                "cut_in_warning_lead_s_min": min(self.leads_s) if s and self.leads_s else None,
                "cut_in_leads_s": [round(v, 3) for v in self.leads_s] if s else None,
                "false_warnings": self.false_warnings + unjustified if s else None,
                "false_warnings_per_min": (self.false_warnings + unjustified) / minutes if s and minutes else None}


@dataclass(frozen=True)
class _Side:
    """A vehicle near the ego on one frame, in the ego lane's frame."""

    x_m: float  # its centre ahead of the ego's [m]
    lateral_m: float  # its centre from the ego lane's centre [m] (+ left)
    lateral_speed_mps: float  # [m/s] (+ left)
    length_m: float  # [m]
    width_m: float  # [m]


class CollisionRecorder:
    """Who moved into whom when the ego first collides: the vehicles it touches (``gt.collided_with``), each with
    ``kind`` "rear-end" (the bodies meet end to end: the overlap along the lane is the smaller) or "side", and
    ``mover``: the one moving sideways towards the other faster than LATERAL_MOVE_MPS (averaged over the last
    COLLISION_WINDOW_S), else in a rear-end the one behind, else the one moving more towards the other."""

    def __init__(self):
        self.records: list[dict] = []
        self._done = False
        self._recent: deque = deque()  # (time [s], ego lateral speed [m/s], {vehicle id: _Side})

    def update(self, gt) -> None:
        near = {o.obj_id: _Side(float(o.position_m[0]), lateral_from_ego_lane(gt.lane, o),
                                lane_velocity(gt.lane, o)[1], float(o.size_m[0]), float(o.size_m[1]))
                for o in gt.objects if o.obj_id in gt.collided_with or abs(o.position_m[0]) < 20.0}
        self._recent.append((gt.time_s, ego_lane_velocity(gt)[1], near))
        while self._recent and gt.time_s - self._recent[0][0] > COLLISION_WINDOW_S:
            self._recent.popleft()
        if self._done or not gt.crashed:
            return
        self._done = True
        if gt.pedestrians_hit and not gt.collided_with:
            return
        for other in gt.collided_with or (None,):
            self.records.append(self._record(gt, other))

    def _record(self, gt, other) -> dict:
        rec = {"time_s": round(gt.time_s, 4), "other_id": other, "mover": None, "kind": None}
        frames = [(ve, near[other]) for _, ve, near in self._recent if other in near]
        if not frames:
            return rec
        o = frames[-1][1]
        # the other's centre relative to the ego's, along and across the lane
        dx, dy = o.x_m, o.lateral_m - gt.lane.offset_m
        # overlap of the bodies along and across: (L_o + L_e)/2 - |dx|, (W_o + W_e)/2 - |dy|
        along, across = (o.length_m + EGO_LENGTH_M) / 2 - abs(dx), (o.width_m + EGO_WIDTH_M) / 2 - abs(dy)
        kind = "rear-end" if along < across else "side"
        side = math.copysign(1.0, dy)
        # speeds towards the other: the other's -s v_o, the ego's s v_e (s: the side the other is on)
        to_ego = -side * sum(f[1].lateral_speed_mps for f in frames) / len(frames)
        to_other = side * sum(f[0] for f in frames) / len(frames)
        if max(to_ego, to_other) > LATERAL_MOVE_MPS or kind == "side":
            mover = "other" if to_ego > to_other else "ego"
        else:
            mover = "ego" if dx > 0 else "other"
        return rec | {"mover": mover, "kind": kind}
