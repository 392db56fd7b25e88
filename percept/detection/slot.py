"""The vision pedestrians slot: the constrained HOG search, each person's range from their ground contact and the
stereo pair, tracking on the ground plane, and a braking request for the nearest person in the ego path or
walking into it.

Each frame the search covers a share of the pyramid's levels over the corridor (every level once in ``sweep_frames``
frames, those of the far field, people up to ``far_person_px`` tall, once in ``far_sweep_frames``: a person appears
first in the far field, where people change scale slowly) and, every frame, the two levels around each tracked
person's predicted window. A lone window (one that grouping would
drop: often all the far field gives in rain) counts only where the stereo pair agrees that something stands where
its feet touch the road. Only confirmed tracks act, and only once the stereo pair has seen them stand where their
feet touch the road (``STEREO_HITS``), and not while their detections show them moving over the ground like a
vehicle (``PersonTrack.too_fast``); a track walking sideways counts as walking only when it has ``WALK_HITS``
detections and its lateral speed is a person's and clear of its own uncertainty (``WALK_SIGMAS`` standard
deviations, and at least ``WALK_MIN_MPS``), so that people standing or walking along the verge do not cause
braking. A track too young for its motion to be known (fewer than ``WALK_HITS`` detections) asks only once the
car could no longer wait a frame and still stop short of it at ``YOUNG_STOP_MPS2`` (at ``YOUNG_FAST_STOP_MPS2``
while its free motion reads faster than ``TrackConfig.vehicle_min_mps``). When a track the slot asked to stop for
turns out to move like a vehicle, the slot withdraws the request (``BrakingRequest.withdrawn``), so that the stop
committed to for it is dropped; so too when it is lost from view young (before ``WALK_HITS``) with its free motion
faster than ``TrackConfig.vehicle_min_mps`` (more likely a vehicle's than a walk); a person lost from view
otherwise keeps the stop committed to for them. The conflict rule is the privileged slot's
(``percept.sensors.conflict``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from percept.sensors import BrakingRequest, EgoMotionGate, EgoPath, Frame, ObjectKind, StereoRig
from percept.sensors.conflict import PERSON_STOP_MARGIN_M, person_conflict
from percept.sensors.vehicle import bumper_gap_m

from .constrained import FEET_MARGIN_PX, PERSON_PX, ConstrainedSearch, SearchConfig, SearchStats, person_box
from .hog import WINDOW_PX, LinearModel
from .pyramid import Detection
from .stereo_range import best_match, box_depth, texture_side
from .tracking import PersonTrack, PersonTracker, TrackConfig

DEFAULT_LANE_WIDTH_M = 3.5
"""Lane width assumed when the path follows no lane [m]."""
WALK_MIN_MPS = 0.5
"""A track's lateral speed below this is standing, whatever its uncertainty [m/s]."""
WALK_MAX_MPS = 3.0
"""A lateral speed above this is no person's walk but a tracking error [m/s]."""
WALK_HITS = 8
"""Detections a track needs before its speed is trusted (about half a second)."""
WALK_SIGMAS = 2.5
"""A track's lateral speed must stand this many of its standard deviations clear of zero to count as walking."""
YOUNG_STOP_MPS2 = 6.5
"""A track with fewer than ``WALK_HITS`` detections asks for braking only once waiting one more frame would leave
less room than a stop at this deceleration needs [m/s²]: in its first detections a vehicle's corner read as a
person cannot be told from one (the free motion's speed is known to +-15 m/s after three), and a request commits
the car to stop."""
YOUNG_FAST_STOP_MPS2 = 7.5
"""The same for a young track whose free motion reads faster than ``TrackConfig.vehicle_min_mps`` (more likely a
vehicle's than a walk, not yet clearly so): it waits until a stop would need this deceleration, 0.5 m/s² short of
the strongest braking, which gives the free motion a few more frames to show a vehicle [m/s²]."""
STANDING_MPS = 0.3
"""At or below this speed the car stands, and what the slot has asked for is settled [m/s]."""
STEREO_HITS = 1
"""Detections a track needs whose stereo depth agreed with their ground contact before it may ask for braking: a
person stands where their feet touch the road; lane paint under dark scenery at night, which the detector can take
for legs, does not give the stereo pair anything to match at the feet's depth."""


@dataclass(frozen=True)
class PedestrianDebug:
    """detections: this frame's windows (best first); tracks: every track after this frame; levels: the pyramid
    levels swept over the corridor this frame; stats: the search's window counts (None on a dropped frame);
    request_track: the track the braking request is for, or None."""

    detections: tuple[Detection, ...]
    tracks: tuple[PersonTrack, ...]
    levels: tuple[int, ...]
    stats: SearchStats | None
    request_track: int | None

    @property
    def reported(self) -> tuple[PersonTrack, ...]:
        """The people the slot reports as seen: confirmed tracks detected within the last few frames (tracks
        coasting longer still act on braking)."""
        return tuple(t for t in self.tracks if t.seen)


def window_of(person: tuple[float, float, float, float]) -> tuple[float, float, float, float]:
    """The detection window around a person box: the person is its middle 96/128 rows, the window is 1:2."""
    u0, v0, u1, v1 = person
    h = (v1 - v0) * WINDOW_PX[1] / (WINDOW_PX[1] - 2 * FEET_MARGIN_PX)
    cu, cv = (u0 + u1) / 2, (v0 + v1) / 2
    return (cu - h / 4, cv - h / 2, cu + h / 4, cv + h / 2)


class PedestrianSlot:
    """``step(frame, upstream)`` -> (BrakingRequest or None, PedestrianDebug); upstream[EgoPath]: the ego path."""

    def __init__(self, rig: StereoRig, dt_s: float, model: LinearModel | None = None,
                 search: SearchConfig = SearchConfig(), tracking: TrackConfig = TrackConfig(), sweep_frames: int = 8,
                 far_sweep_frames: int = 3, far_person_px: float = 40.0):
        if sweep_frames < 1 or far_sweep_frames < 1:
            raise ValueError(f"sweep_frames and far_sweep_frames must be at least 1, got {sweep_frames} and "
                             f"{far_sweep_frames}")
        self.search = ConstrainedSearch(rig, model if model is not None else LinearModel.inria(), search)
        self.tracker = PersonTracker(rig, dt_s, tracking)
        # the stereo match's compiled passes, loaded now rather than in a frame
        texture_side(np.zeros((6, 3), np.uint8), 1.0)
        best_match(np.zeros(3, np.float32))
        # frames between two searches of each level: the far field's levels (people up to far_person_px tall)
        # every far_sweep_frames, where crossing people are first found; the levels above them, which only find
        # again people whose track was lost, every sweep_frames
        self.periods = tuple(far_sweep_frames if PERSON_PX * s <= far_person_px else sweep_frames
                             for s in self.search.scales)
        self.cam_x = float(rig.camera_position()[0])
        self.motion = EgoMotionGate()
        self.vehicle_min_mps = tracking.vehicle_min_mps
        self.asked: dict[int, PersonTrack] = {}  # the tracks asked for since the car last stood, as last seen

    def reset(self) -> None:
        self.tracker.reset()
        self.motion.reset()
        self.asked = {}

    def step(self, frame: Frame, upstream: dict) -> tuple[BrakingRequest | None, PedestrianDebug]:
        """One frame: search, track, and the braking request (or its withdrawal) for the nearest person in the path."""
        motion = self.motion.update(frame)
        speed, yaw_rate = motion.speed_mps, motion.yaw_rate_rps
        path = upstream.get(EgoPath) or EgoPath.straight(speed)
        predicted = self.tracker.predict(speed, yaw_rate)
        if frame.left is None:
            tracks = self.tracker.update([], [], seen=False)
            dets, levels, stats = [], (), None
        else:
            levels = tuple(k for k, p in enumerate(self.periods) if k % p == frame.index % p)
            dets, stats = self.search.search(frame.left, path, levels, rois=[window_of(b) for b in predicted])
            boxes = [person_box(d.box_px) for d in dets]
            # a lone window is a person only where the stereo pair agrees with its ground contact
            tracks = self.tracker.update(boxes, [d.score for d in dets], stereo=self._stereo(frame) if boxes else None,
                                         verify=[d.windows < 2 for d in dets])
        request, rid = self.request(tracks, path, speed)
        self.asked.update({t.track_id: t for t in tracks if t.track_id in self.asked or t.track_id == rid})
        if rid is None and speed <= STANDING_MPS:
            self.asked = {}
        elif rid is None:
            request = self._withdrawal(tracks, speed)
        return request, PedestrianDebug(tuple(dets), tuple(tracks), levels, stats, rid)

    def _stereo(self, frame: Frame):
        """A box's stereo depth (Z, sigma_Z) [m] in this frame, searched about its ground-contact depth (None where
        it fails), for the tracker's measurements; None without a right image."""
        if frame.right is None:
            return None
        return lambda box, z_ground_m: box_depth(frame.left, frame.right, box, self.tracker.rig, z_ground_m)

    def request(self, tracks: list[PersonTrack], path: EgoPath, speed: float):
        """(the braking request, its track id) for the nearest track that may act and conflicts with the path, or
        (None, None)."""
        lane_w = path.lane.width_m if path.follows_lane else DEFAULT_LANE_WIDTH_M
        best = None
        for t in tracks:
            if not t.confirmed or t.stereo_hits < STEREO_HITS or t.too_fast:
                continue
            vy = t.velocity_mps[1]
            # walking sideways only when the track is old enough to have a speed, the speed is a person's and it
            # stands clear of its uncertainty
            walking = (t.hits >= WALK_HITS and abs(vy) <= WALK_MAX_MPS
                       and abs(vy) > max(WALK_MIN_MPS, WALK_SIGMAS * t.sigma_vy_mps))
            # a person taken to stand is where they were last seen, not carried on by a speed not trusted
            x, y = t.position_m if walking else t.standing_m
            c = person_conflict(x, y, vy if walking else 0.0, float(path.centre_y(x)), lane_w, speed)
            # (once asked, a track is asked for until it is withdrawn)
            if c.any and t.hits < WALK_HITS and t.track_id not in self.asked and self._can_wait(x, speed, t):
                continue
            if c.any and (best is None or x < best[0]):
                best = (x, t, c)
        if best is None:
            return None, None
        x, t, c = best
        why = "pedestrian in the path" if c.now else "pedestrian stepping into the path"
        return self._braking_request(x, speed, why, t.track_id), t.track_id

    def _braking_request(self, x_m: float, speed_mps: float, why: str, track_id: int,
                         withdrawn: bool = False) -> BrakingRequest:
        """The request about a track whose feet are x_m ahead of the vehicle frame's origin."""
        # range: the left camera's depth of the feet; its rate: the ego's speed alone, the person taken to stand along
        # the road, because the track's own x speed comes from depths whose noise grows with Z^2 and would flip the
        # following law's standing test (ego speed - closing < 1 m/s) frame to frame for a far person. People cross;
        # one walking along the path at 1.5 m/s changes the closing speed by a tenth at 15 m/s.
        return BrakingRequest(x_m - self.cam_x, -speed_mps, why, ObjectKind.PEDESTRIAN, track_id, withdrawn=withdrawn)

    def _can_wait(self, x_m: float, speed_mps: float, t: PersonTrack) -> bool:
        """Whether the car could drive one more frame towards a young track at x_m and still stop short of it (at
        ``YOUNG_FAST_STOP_MPS2`` when its free motion reads a vehicle's speed, otherwise ``YOUNG_STOP_MPS2``)."""
        room = bumper_gap_m(x_m - self.cam_x) - PERSON_STOP_MARGIN_M - speed_mps * self.tracker.dt_s
        a = YOUNG_FAST_STOP_MPS2 if t.free_speed_mps > self.vehicle_min_mps else YOUNG_STOP_MPS2
        # the distance a stop at a takes: v^2 / (2 a)
        return room > speed_mps * speed_mps / (2 * a)

    def _withdrawal(self, tracks: list[PersonTrack], speed: float) -> BrakingRequest | None:
        """With nothing to ask for: the request withdrawn when every track asked for since the car last stood moves
        like a vehicle: shown so (``too_fast``), or lost from view before ``WALK_HITS`` detections with its free
        speed above ``TrackConfig.vehicle_min_mps`` (more likely a vehicle's than a walk). A person asked for and
        lost from view otherwise keeps the stop committed to for them."""
        now = {t.track_id for t in tracks}

        def vehicle(t: PersonTrack) -> bool:
            if t.track_id in now:
                return t.too_fast
            return t.hits < WALK_HITS and t.free_speed_mps > self.vehicle_min_mps

        if not self.asked or not all(vehicle(t) for t in self.asked.values()):
            return None
        t = self.asked[max(self.asked)]
        self.asked = {}
        return self._braking_request(t.position_m[0], speed, "moves like a vehicle, not a person", t.track_id,
                                     withdrawn=True)
