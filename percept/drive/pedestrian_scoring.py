"""Scoring the pedestrians task: stops for crossing people, false stops and brakings for no one, and the vision
slot's reported people against the true boxes (docs/design.md, "Scoring definitions", Pedestrians)."""

from __future__ import annotations

import numpy as np

from percept.detection.constrained import SearchConfig
from percept.detection.metrics import DetectionTally, eligible
from percept.sensors import BrakingRequest, ObjectKind

from .privileged import true_centre_y
from .scoring import HALTING_VEHICLE_MPS, STOP_SPEED_MPS, ScoreContext, StepTruth, hard_braking

MATCH_M = 3.0
"""How far a vision track may lie from the true person it stands for [m], across; along the range, this plus one
disparity pixel of the rig's range resolution (``person_matches``)."""


def person_matches(track_xy, person_xy, stereo_fb_px_m: float | None) -> bool:
    """Whether a vision track at ``track_xy`` (vehicle frame, x ahead [m]) stands for the true person at
    ``person_xy``: within MATCH_M across and, along x, within MATCH_M plus the range one disparity pixel spans at the
    track's range, dZ = Z^2 / (f b) (5.9 m at 42 m on the default rig): a person stereo read a pixel short is still
    that person, not "no one". Within MATCH_M of each other on the ground always matches (without a rig, only that)."""
    dx, dy = abs(person_xy[0] - track_xy[0]), abs(person_xy[1] - track_xy[1])
    if np.hypot(dx, dy) < MATCH_M:
        return True
    if stereo_fb_px_m is None or not stereo_fb_px_m > 0:
        return False
    # Z: the track's x, from the vehicle's centre (the cameras sit 0.8 m ahead of it on the default rig: a little more
    # room than the range itself gives)
    z = max(float(track_xy[0]), 0.0)
    # one disparity pixel of range at Z: Z^2 / (f b)
    return dy < MATCH_M and dx < MATCH_M + z * z / stereo_fb_px_m


class PedestrianScorer:
    """Stops for crossing pedestrians and false stops; with the vision slot, its reported people (confirmed tracks'
    boxes) against the true boxes of every frame. A true pedestrian counts (``eligible``: at least 24 px tall and
    half visible) inside the searched domain (the search's depths and corridor about the true lane centre); the
    others are ignore regions. ``verge_brakes``: hard brakings (below -3 m/s², above a walking pace) that begin on a
    braking request for a person who is not crossing (the request's person: the truth's id for the privileged slot,
    the true pedestrian nearest the requesting track for the vision slot, if it lies within ``MATCH_M`` across and
    within ``MATCH_M`` plus one disparity pixel of range along, ``person_matches``); ``brakes_for_no_one``: those
    that begin on a request for no true person at all. ``false_stops``: stops that nothing in the path calls for (no
    crossing person within 40 m ahead, no vehicle in the path slower than HALTING_VEHICLE_MPS). The last two are
    scored in every scenario: the pedestrian slot can stop the car for a person who is not there, on any road."""

    def __init__(self, ctx: ScoreContext):
        self.ctx = ctx
        self.tally = DetectionTally() if ctx.vision else None
        self.domain = SearchConfig()
        self.crossing_seen: dict = {}
        self.crossing_stopped: dict = {}
        self.false_stops = 0
        self.verge_brakes = 0
        self.brakes_for_no_one = 0
        self._stopped = False
        self._braking = False

    def update(self, request, debug, step: StepTruth) -> None:
        gt, obstacle = step.truth, step.in_path
        # a crossing person counts as stopped for if the ego halts while it is within 40 m ahead
        stopped = gt.speed_mps < STOP_SPEED_MPS
        near_crossing = False
        for o in gt.objects:
            if o.kind is ObjectKind.PEDESTRIAN and o.crossing and 0 < o.position_m[0] < 40:
                self.crossing_seen.setdefault(o.obj_id, True)
                near_crossing = True
                if stopped:
                    self.crossing_stopped[o.obj_id] = True
        # a stop with no crossing pedestrian near is a false stop (for a roadside one, or for no one), unless a
        # vehicle in the path halts us (a lead driving on ahead does not)
        halted = (obstacle is not None and obstacle.kind is ObjectKind.VEHICLE
                  and obstacle.speed_mps < HALTING_VEHICLE_MPS)
        if stopped and not self._stopped and not near_crossing and not halted:
            self.false_stops += 1
        self._stopped = stopped
        braking = hard_braking(step)
        if braking and not self._braking and BrakingRequest.asking(request) is not None:
            person = self._requested_person(request, debug, gt)
            self.verge_brakes += int(person is not None and not person.crossing)
            self.brakes_for_no_one += int(person is None)
        self._braking = braking
        if self.tally is not None and debug is not None:
            self._score_detections(debug, gt)

    def _requested_person(self, request, debug, gt):
        """The true pedestrian a braking request is for, or None."""
        people = [o for o in gt.objects if o.kind is ObjectKind.PEDESTRIAN]
        tracks = {t.track_id: t for t in getattr(debug, "tracks", ())}
        if request.obj_id in tracks:  # a vision track: the true person nearest it on the ground, if close enough
            x, y = tracks[request.obj_id].position_m
            near = min(people, key=lambda o: np.hypot(o.position_m[0] - x, o.position_m[1] - y), default=None)
            ok = near is not None and person_matches((x, y), near.position_m[:2], self.ctx.stereo_fb_px_m)
            return near if ok else None
        return next((o for o in people if o.obj_id == request.obj_id), None)

    def _score_detections(self, debug, gt) -> None:
        lane, dom = gt.lane, self.domain
        boxes, ok, ids, ranges = [], [], [], []
        for o in gt.objects:
            if o.kind is not ObjectKind.PEDESTRIAN or o.box_px is None:
                continue
            yc = true_centre_y(lane, o.position_m[0])
            inside = (dom.min_range_m <= o.distance_m <= dom.max_range_m
                      and abs(o.position_m[1] - yc) <= dom.half_width_m)
            boxes.append(o.box_px)
            ok.append(inside and eligible(np.asarray(o.box_px), min(max(o.visible, 0.0), 1.0)))
            ids.append(o.obj_id)
            ranges.append(o.distance_m)
        people = debug.reported
        self.tally.add([t.box_px for t in people], [t.score for t in people], boxes, ok, ids, ranges)

    def result(self) -> dict:
        stops = [bool(self.crossing_stopped.get(k, False)) for k in sorted(self.crossing_seen)]
        det = self.tally.result() if self.tally is not None else {}
        out = {"recall": det.get("recall"), "precision": det.get("precision"), "fppi": det.get("fppi"),
               "recall_by_height": det.get("recall_by_height"),
               # the counts behind the rates, so that a batch can pool its runs' frames
               "counts": {k: det[k] for k in ("tp", "fp", "fn", "frames")} | {"by_height": det["matched_by_height"]}
               if det else None,
               "first_detection_range_m": det.get("first_detection_range_m"),
               "stops": stops if self.ctx.crossing_pedestrians else None,
               "false_stops": self.false_stops,
               "verge_brakes": self.verge_brakes if self.ctx.pedestrians else None,
               "brakes_for_no_one": self.brakes_for_no_one}
        # the people model, where a vision slot used one
        return out | ({"detector": self.ctx.detector} if self.ctx.vision else {})
