"""The vision neighbours slot: both rigs' stereo pairs and the ego path in, every vehicle in the ego lane and the
lanes beside it, ahead, beside and behind, out (``Neighbours``).

Each frame each rig's vehicles are found (``finder``: band stereo, ground-grid groups, the face's subpixel range) in
the ego lane's coordinates, tracked (``tracker``), and each confirmed track reported with its lane, gap, relative
speed, lateral position and speed in its lane, and uncertainties. Intent: a neighbour in a lane beside, going along
the road (at least ``min_ground_speed_mps`` over the ground: a person crossing is the pedestrian task's), whose
lateral speed (beyond ``speed_sigmas`` of its estimate) takes its centre to the ego lane's boundary within
``horizon_s``, and which was a settled neighbour first (seen in that lane ``TrackerConfig.min_settled`` times in a row
since it was laterally still there: a car changing into it from the lane beyond, or a ramp's car arriving in the
acceleration lane, is not cutting in to the ego's) or, not settled, has gone on ``through_shift_m`` past its lane's
centre towards the ego lane (a ramp's car merging straight on), is flagged as cutting in, with the predicted time to
that crossing, so the following law can treat it as a lead before it arrives; the flag stays on while it is tracked
in the ego lane after, so that the car is not lost before the lead's own slot takes it up close by.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from percept.sensors import EGO_LENGTH_M, EgoPath, Frame, Neighbour, Neighbours, StereoRig, Zone, zone_and_gap

from .clusters import DEFAULT_LANE_WIDTH_M, VEHICLE_LENGTH_M, Detection
from .finder import RigFinder
from .tracker import NeighbourTracker, Track, TrackerConfig


@dataclass(frozen=True)
class NeighbourConfig:
    """What the slot covers and when it warns."""

    ahead_m: float = Neighbours.ahead_m  # covered ahead of the ego: the largest bumper gap reported [m]
    behind_m: float = Neighbours.behind_m  # covered behind it [m]
    front_near_m: float = 3.0  # the nearest face the front rig measures, along the lane [m]
    rear_near_m: float = -3.0  # the nearest face the rear rig measures [m]
    horizon_s: float = 3.0  # a cut-in is flagged when the boundary is this close in time [s]
    min_lateral_speed_mps: float = 0.3  # and the lateral speed towards it at least this [m/s]
    speed_sigmas: float = 2.0  # and at least this many sigmas of its estimate [-]
    min_shift_m: float = 0.25  # and it has moved at least this from its lane's centre towards the ego lane [m]
    min_seen_share: float = 0.5  # and a rig found it on at least this share of the last TrackerConfig.recent_s (a
    # car in view is found on nearly every frame; stereo's phantoms, from edges on the road or a guard rail, come
    # and go) [-]
    warn_ahead_m: float = 70.0  # cut-ins are flagged for centres up to this far ahead: a car crossing at a 60 m gap
    # (65 m centre) a second after its warning, closing at 5 m/s; beyond, its lateral position is too uncertain [m]
    max_ground_speed_mps: float = 50.0  # a track faster than this over the ground (180 km/h) is no car on the road but
    # things matched by chance, such as posts, strung into one track: it is not reported [m/s]
    min_ground_speed_mps: float = 5.0  # a cut-in is a vehicle going along the road: anything slower there (a person
    # crossing, whom the pedestrian task watches) is not flagged [m/s]
    veer_shift_sigmas: float = 3.0  # a manoeuvre stands in for the lateral speed's significance only once the car
    # has left its lane's centre by this many sigmas of its lateral place (far away a face's place wanders in runs) [-]
    through_shift_m: float = 0.7  # a track not settled in its lane (moving over from the lane beyond, or a ramp's
    # car) cuts in once it is this far past its lane's centre towards the ego lane, still moving: one that settles
    # in its lane stops short of that [m]


@dataclass(frozen=True)
class NeighbourDebug:
    """What the review shows: each rig's detections this frame and how long the slot's parts took."""

    detections: dict  # rig name -> list of Detection
    points: dict  # rig name -> number of standing points


class NeighbourSlot:
    """Vision neighbours from the forward rig and, when the car has one, the rear rig."""

    def __init__(self, rig: StereoRig, rear_rig: StereoRig | None, dt_s: float,
                 cfg: NeighbourConfig = NeighbourConfig(), tracker: TrackerConfig = TrackerConfig()):
        self.cfg = cfg
        # faces lie half the ego's length beyond the gap
        reach = EGO_LENGTH_M / 2 + 2.0
        self.front = RigFinder(rig, cfg.front_near_m, cfg.ahead_m + reach)
        self.rear = RigFinder(rear_rig, -cfg.behind_m - reach, cfg.rear_near_m) if rear_rig else None
        self.tracker = NeighbourTracker(dt_s, tracker)
        self._index: int | None = None  # the lane estimate's index on the last frame with one

    def reset(self) -> None:
        self.tracker.reset()
        self._index = None

    def step(self, frame: Frame, upstream: dict) -> tuple[Neighbours, NeighbourDebug]:
        path: EgoPath = upstream[EgoPath]
        lane = path.lane if path.follows_lane else None
        width = float(lane.width_m) if lane is not None else DEFAULT_LANE_WIDTH_M
        if lane is not None:
            # the ego's lane moved (a lane change): every track's lateral position is now from the new lane's centre
            if self._index is not None and lane.index != self._index:
                self.tracker.shift_lanes((lane.index - self._index) * width)
            self._index = lane.index
        detections: dict[str, list[Detection]] = {}
        points = {}
        if not frame.dropped:
            detections["front"], pts = self.front.find(frame.left_gray, frame.right_gray, lane)
            points["front"] = len(pts)
        if self.rear is not None and frame.has_rear:
            detections["rear"], pts = self.rear.find(frame.rear_left_gray, frame.rear_right_gray, lane)
            points["rear"] = len(pts)
        self.tracker.step(detections, width, path.speed_mps)
        tracks = [self._report(t, width, path.speed_mps) for t in self.tracker.tracks if t.confirmed]
        tracks = [n for n in tracks if n is not None]
        tracks.sort(key=lambda n: (n.lane, abs(n.x_m)))
        rear = self.rear is not None and frame.has_rear
        return Neighbours(tuple(tracks), self.cfg.ahead_m, self.cfg.behind_m, rear), NeighbourDebug(detections, points)

    def _intent(self, t: Track, lat: float, vl: float, lane: int, width: float, sig_l: float, sig_vl: float,
                ground_mps: float) -> tuple[bool, float | None]:
        """(cutting in, predicted time to the ego lane's boundary [s]) of a track in a lane beside, or in the ego lane
        after a warning; ``sig_l``, ``sig_vl``: the 1-sigmas of its lateral place [m] and speed [m/s]; ``ground_mps``:
        its along-lane speed over the ground [m/s]. It starts when the track, going
        at least ``min_ground_speed_mps``, measured this frame (a face cut off by the image's edge counts: a car
        pulling out close by always is) and on ``min_seen_share`` of the recent ones, moves towards the ego lane
        faster than both ``min_lateral_speed_mps`` and ``speed_sigmas`` of that speed's estimate (or than the former
        alone while its filter's innovations say it manoeuvres that way, ``NeighbourTracker.manoeuvring``, and it is
        ``veer_shift_sigmas`` of its lateral place off its lane's centre towards the ego lane), has left
        its lane's centre towards it by ``min_shift_m`` (settled in its lane) or ``through_shift_m`` (not settled) and
        will reach the boundary within ``horizon_s``; it holds while the car stays shifted that way and does not move
        back (a merging car may pause on the line), and once it is in the ego lane (time to crossing 0)."""
        c = self.cfg
        if lane == 0:  # flagged on its way in: it stays a target while it is tracked in the ego lane
            return True, 0.0
        # towards the ego lane: -sign(l) l' > 0; shift from its lane's centre towards it: -sign(l) (l - lane w)
        inward = -math.copysign(1.0, lat)
        toward, shift = inward * vl, inward * (lat - lane * width)
        if t.warning:
            holds = shift >= c.min_shift_m and toward > -c.min_lateral_speed_mps
        else:
            settled = t.settled >= self.tracker.cfg.min_settled
            # a manoeuvre towards the ego lane (a run of innovations that way: -sign(l) veer > 0) already tells a
            # move from noise, and its larger process noise widens sig_vl just as the car starts over; it counts once
            # the car is off its lane's centre beyond its place's noise: shift > k sigma_l
            veering = self.tracker.manoeuvring(t) and inward * t.veer > 0 and shift > c.veer_shift_sigmas * sig_l
            holds = (t.camera is not None and t.seen >= c.min_seen_share * self.tracker.recent_frames
                     and ground_mps >= c.min_ground_speed_mps
                     and shift >= (c.min_shift_m if settled else c.through_shift_m)
                     and toward > max(c.min_lateral_speed_mps, 0.0 if veering else c.speed_sigmas * sig_vl))
        if not holds:
            return False, None
        # its centre reaches the boundary |l| = w/2 after t = (|l| - w/2) / max(-sign(l) l', v_min)
        ttc = max(abs(lat) - width / 2, 0.0) / max(toward, c.min_lateral_speed_mps)
        return (True, ttc) if t.warning or ttc <= c.horizon_s else (False, None)

    def _report(self, t: Track, width: float, speed_mps: float) -> Neighbour | None:
        """The record of track ``t`` for an ego at ``speed_mps`` [m/s] (its along-lane speed over ground is
        speed_mps + x'), or None when it is beyond the lanes and ranges reported or faster than any car."""
        x, vx, lat, vl = (float(v) for v in t.kf.x[:, 0])
        lane = int(round(lat / width))
        zone, gap = zone_and_gap(x, VEHICLE_LENGTH_M)
        if abs(lane) > 1 or gap > (self.cfg.ahead_m if zone is Zone.AHEAD else self.cfg.behind_m):
            return None
        ground_mps = speed_mps + vx
        if ground_mps > self.cfg.max_ground_speed_mps:
            return None
        P = t.kf.P
        warn = (lane != 0 or t.warning) and zone is not Zone.BEHIND and x <= self.cfg.warn_ahead_m
        sig_l, sig_vl = math.sqrt(max(P[2, 2], 0.0)), math.sqrt(max(P[3, 3], 0.0))
        cut_in, ttc = self._intent(t, lat, vl, lane, width, sig_l, sig_vl, ground_mps) if warn else (False, None)
        t.warning = cut_in
        return Neighbour(t.track_id, lane, zone, x, gap, vx, lat - lane * width, vl, VEHICLE_LENGTH_M,
                         self.tracker.sigma_x(t), math.sqrt(max(P[1, 1], 0.0)), sig_l, t.camera, t.box_px, cut_in, ttc)
