"""The vehicles in the ego lane and the lanes either side, from ground truth: the ``Neighbours`` record the
neighbours task's slots return, as the privileged slot reports it and as its scorer takes the truth.

Each vehicle's lane comes from its centre's lateral position against the true ego lane's centre line
(``LaneTruth``: y_c(x) = -offset - tan(heading) x + curvature x^2 / 2), in lane widths. Along-lane positions are the
vehicle-frame x of its centre: on highway-env's roads (curvature below 1/500 m, headings within a few degrees of the
lane) the arc length along the lane differs from x by well under 0.5 % within 80 m.
"""

from __future__ import annotations

import math

from percept.sensors import Frame, Neighbour, Neighbours, ObjectKind, Zone, zone_and_gap

from .privileged import TruthSlot, true_centre_y

CUT_IN_HORIZON_S = 3.0
"""A neighbour whose lateral speed takes its centre to the ego lane's boundary within this is cutting in [s]."""
CUT_IN_MIN_SPEED_MPS = 0.1
"""Below this lateral speed towards the ego lane a neighbour is keeping its lane, not cutting in [m/s]."""
SEEN_SHARE = 0.5
"""A rig sees a vehicle when at least this share of it is visible in its left camera."""


def lane_heading_rad(lane, x_m: float) -> float:
    """The true ego lane's direction x_m ahead, relative to the vehicle's x axis [rad] (+ counter-clockwise)."""
    # the slope of the centre line: dy_c/dx = -tan(heading) + curvature x
    return math.atan(-math.tan(lane.heading_rad) + lane.curvature_1pm * x_m)


def lane_velocity(lane, obj) -> tuple[float, float]:
    """An object's (along-lane, lateral) velocity [m/s] in the true ego lane's frame at its position (+ ahead,
    + left), from its speed and its yaw relative to the ego less the lane's direction there."""
    rel = obj.yaw_rad - lane_heading_rad(lane, obj.position_m[0])
    return obj.speed_mps * math.cos(rel), obj.speed_mps * math.sin(rel)


def ego_lane_velocity(gt) -> tuple[float, float]:
    """The ego's (along-lane, lateral) velocity [m/s] in its lane's frame (+ ahead, + left)."""
    h = gt.lane.heading_rad
    return gt.speed_mps * math.cos(h), gt.speed_mps * math.sin(h)


def lateral_from_ego_lane(lane, obj) -> float:
    """An object's centre from the true ego lane's centre line at its x [m] (+ left)."""
    return obj.position_m[1] - true_centre_y(lane, obj.position_m[0])


def cut_in(lane: int, lateral_m: float, lateral_speed_mps: float, width_m: float,
           horizon_s: float = CUT_IN_HORIZON_S) -> tuple[bool, float | None]:
    """Whether a neighbour in ``lane`` (+-1) at ``lateral_m`` from its lane's centre, moving at ``lateral_speed_mps``
    (+ left), reaches the ego lane's boundary within ``horizon_s`` at constant lateral speed, and when [s].

    Only a neighbour at or past its own lane's centre on the ego's side counts: one still settling into its lane
    from the far side (after a lane change from two lanes away) moves towards the ego lane too, but stops at the centre.
    """
    if lane == 0:
        return False, None
    toward = -lane * lateral_speed_mps
    # distance from its centre to the ego lane's boundary on its side: w/2 + s lateral (s = lane, +-1)
    room = width_m / 2 + lane * lateral_m
    if toward < CUT_IN_MIN_SPEED_MPS or lane * lateral_m > 0:
        return False, None
    # t = room / lateral speed towards the ego lane
    t = max(room, 0.0) / toward
    return (True, t) if t <= horizon_s else (False, None)


def seen_by(obj) -> tuple[str | None, tuple | None]:
    """The rig that sees ``obj`` (at least SEEN_SHARE visible) and its box there: ("front", box_px),
    ("rear", rear_box_px), or (None, None); the better-seen one when both do."""
    front = obj.visible if obj.box_px is not None else 0.0
    rear = obj.rear_visible if obj.rear_box_px is not None else 0.0
    if max(front, rear) < SEEN_SHARE:
        return None, None
    return ("front", obj.box_px) if front >= rear else ("rear", obj.rear_box_px)


def truth_neighbour(gt, obj, horizon_s: float = CUT_IN_HORIZON_S) -> Neighbour | None:
    """The ``Neighbour`` of a true vehicle ``obj`` of the ground truth ``gt``, or None when its centre is not in the
    ego lane or a lane beside it. Sigmas are 0."""
    lane, w = gt.lane, gt.lane.width_m
    d = lateral_from_ego_lane(lane, obj)
    # its lane, in lane widths from the ego's (a centre on a boundary: the lane on its left)
    k = math.floor(d / w + 0.5)
    if abs(k) > 1:
        return None
    x, length = float(obj.position_m[0]), float(obj.size_m[0])
    zone, gap = zone_and_gap(x, length)
    along, lat_speed = lane_velocity(lane, obj)
    lateral = d - k * w
    flagged, t_cross = cut_in(k, lateral, lat_speed, w, horizon_s)
    camera, box = seen_by(obj)
    return Neighbour(obj.obj_id, k, zone, x, gap, along - ego_lane_velocity(gt)[0], lateral, lat_speed, length,
                     camera=camera, box_px=box, cut_in=flagged, time_to_cross_s=t_cross)


def truth_neighbours(gt, ahead_m: float = Neighbours.ahead_m, behind_m: float = Neighbours.behind_m,
                     horizon_s: float = CUT_IN_HORIZON_S) -> Neighbours:
    """Every vehicle of the ground truth ``gt`` in the ego lane and the lanes either side whose bumper gap is within
    ``ahead_m`` ahead or ``behind_m`` behind (and every one beside), nearest first within each lane (lanes -1, 0,
    +1 in turn), with cut-ins flagged over ``horizon_s``. ValueError on a range or horizon that is not > 0."""
    for name, v in (("ahead_m", ahead_m), ("behind_m", behind_m), ("horizon_s", horizon_s)):
        if not (math.isfinite(v) and v > 0):
            raise ValueError(f"{name} must be a finite number > 0, got {v!r}")
    out = []
    for obj in gt.objects:
        if obj.kind is not ObjectKind.VEHICLE:
            continue
        n = truth_neighbour(gt, obj, horizon_s)
        if n is not None and n.gap_m <= (ahead_m if n.zone is Zone.AHEAD else behind_m):
            out.append(n)
    out.sort(key=lambda n: (n.lane, abs(n.x_m)))
    return Neighbours(tuple(out), ahead_m, behind_m, rear=True)


class PrivilegedNeighbours(TruthSlot):
    """The true vehicles in the ego lane and the lanes either side (``truth_neighbours``, 80 m ahead, 85 m behind)."""

    def step(self, frame: Frame, upstream: dict) -> tuple[Neighbours, None]:
        return truth_neighbours(self.truth.get()), None
