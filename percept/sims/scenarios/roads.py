"""Road networks built from highway-env's own lane classes (StraightLane, CircularLane) and its AbstractLane
(ClothoidLane: the transition curves between them).

All coordinates here are highway-env's (x along travel, y to the right). Lane 0 is the leftmost;
its left line is the solid road edge, the rightmost lane's right line too, lines between lanes dashed.
"""

from __future__ import annotations

import numpy as np
from highway_env.road.lane import CircularLane, LineType, SineLane, StraightLane

from .clothoid import ClothoidLane
from .network import IndexedRoadNetwork

C, S, N = LineType.CONTINUOUS_LINE, LineType.STRIPED, LineType.NONE

SPIRAL_TIME_S = 2.0
"""Transition curve length as travel time at the speed limit (AASHTO Green Book 2018, 3.3.8.2)."""


def line_types(i: int, lanes: int) -> list:
    return [C if i == 0 else S, C if i == lanes - 1 else N]


class _Builder:
    """Chains straight and arc segments of a multi-lane road, tracking the reference (leftmost lane) pose."""

    def __init__(self, lanes: int, width_m: float, speed_limit: float):
        self.net = IndexedRoadNetwork()
        self.lanes, self.w, self.v = lanes, width_m, speed_limit
        self.pos = np.zeros(2)  # centre of lane 0 at the current node
        self.heading = 0.0
        self.kappa = 0.0  # curvature of the reference lane at the current node [1/m], + turning right
        self.k = 0

    def _node(self) -> str:
        return str(self.k)

    def straight(self, length_m: float, end_node: str | None = None) -> None:
        a, b = self._node(), end_node or str(self.k + 1)
        d = np.array([np.cos(self.heading), np.sin(self.heading)])
        right = np.array([-d[1], d[0]])  # highway-env: +90 deg from heading is to the right
        for i in range(self.lanes):
            p0 = self.pos + i * self.w * right
            self.net.add_lane(a, b, StraightLane(p0, p0 + length_m * d, width=self.w,
                                                 line_types=line_types(i, self.lanes), speed_limit=self.v))
        self.pos = self.pos + length_m * d
        self.k += 1

    def arc(self, radius_m: float, angle_rad: float, end_node: str | None = None) -> None:
        """Arc of the reference lane; angle > 0 turns right (clockwise in highway-env's y-down plane)."""
        a, b = self._node(), end_node or str(self.k + 1)
        cw = angle_rad > 0
        d = np.array([np.cos(self.heading), np.sin(self.heading)])
        right = np.array([-d[1], d[0]])
        centre = self.pos + (radius_m if cw else -radius_m) * right
        phi0 = np.arctan2(*(self.pos - centre)[::-1])
        phi1 = phi0 + angle_rad
        for i in range(self.lanes):
            # lanes further right are inside a right turn (smaller radius) and outside a left turn
            r = radius_m - i * self.w if cw else radius_m + i * self.w
            self.net.add_lane(a, b, CircularLane(centre, r, phi0, phi1, clockwise=cw, width=self.w,
                                                 line_types=line_types(i, self.lanes), speed_limit=self.v))
        self.pos = centre + radius_m * np.array([np.cos(phi1), np.sin(phi1)])
        self.heading += angle_rad
        self.kappa = 1.0 / radius_m if cw else -1.0 / radius_m
        self.k += 1

    def spiral(self, kappa_end_1pm: float, length_m: float, end_node: str | None = None) -> None:
        """Clothoid of the reference lane from the current curvature to ``kappa_end_1pm`` (+ right) over length_m."""
        a, b = self._node(), end_node or str(self.k + 1)
        lanes = [ClothoidLane(self.pos, self.heading, length_m, self.kappa, kappa_end_1pm, offset_m=i * self.w,
                              width=self.w, line_types=line_types(i, self.lanes), speed_limit=self.v)
                 for i in range(self.lanes)]
        for lane in lanes:
            self.net.add_lane(a, b, lane)
        self.pos = lanes[0].position(lanes[0].length, 0.0)
        self.heading = lanes[0].heading_at(lanes[0].length)
        self.kappa = kappa_end_1pm
        self.k += 1

    @property
    def spiral_length_m(self) -> float:
        return SPIRAL_TIME_S * self.v

    def transition(self, kappa_end_1pm: float, end_node: str | None = None) -> None:
        """A spiral to the next curvature: 2 s of travel per half (straight to arc); a reverse curve gets both."""
        if kappa_end_1pm != self.kappa:
            halves = 2 if self.kappa * kappa_end_1pm < 0 else 1
            self.spiral(kappa_end_1pm, self.spiral_length_m * halves, end_node)


def straight_road(lanes: int, length_m: float, width_m: float = 4.0,
                  speed_limit: float = 30.0) -> IndexedRoadNetwork:
    """A straight multi-lane road from node "0" to "1"."""
    b = _Builder(lanes, width_m, speed_limit)
    b.straight(length_m)
    return b.net


def winding_road(rng: np.random.Generator, lanes: int = 3, length_m: float = 4000.0, width_m: float = 4.0,
                 speed_limit: float = 25.0) -> IndexedRoadNetwork:
    """Straight lead-in, then arcs of radius 150–600 m turning alternately left and right, each entered and left
    through a clothoid (straight to arc, or arc to reversed arc)."""
    b = _Builder(lanes, width_m, speed_limit)
    b.straight(150.0)
    total, sign = 150.0, float(rng.choice([-1.0, 1.0]))
    while total < length_m:
        r = float(rng.uniform(150.0, 600.0))
        arc_len = float(rng.uniform(120.0, 280.0))
        # every lane's radius within [150, 600] m: right turns put lanes inside, left turns outside
        r = max(r, 150.0 + (lanes - 1) * width_m) if sign > 0 else min(r, 600.0 - (lanes - 1) * width_m)
        b.transition(sign / r)
        b.arc(r, sign * arc_len / r)
        total += arc_len
        if rng.random() < 0.5:
            b.transition(0.0)
            b.straight(float(rng.uniform(40.0, 120.0)))
            total += 60.0
        sign = -sign
    b.transition(0.0)
    b.straight(300.0)
    return b.net


def loop_road(lanes: int = 2, straight_m: float = 1000.0, radius_m: float = 260.0, width_m: float = 4.0,
              speed_limit: float = 25.0) -> IndexedRoadNetwork:
    """A closed circuit: two straights joined by two half turns to the right (clockwise), each a clothoid, an arc
    and a clothoid; ~3.7 km. The halves are point-symmetric, so the circuit closes exactly."""
    b = _Builder(lanes, width_m, speed_limit)
    for end in (None, "0"):
        b.straight(straight_m)
        b.transition(1.0 / radius_m)
        # each clothoid turns by L / (2 R): the arc takes the rest of the half turn
        b.arc(radius_m, np.pi - b.spiral_length_m / radius_m)
        b.transition(0.0, end_node=end)
    return b.net



MERGE_GAP_M = 6.5
"""highway-env's merge-v0: the ramp's centre runs this far outside the next lane's centre before it converges [m]."""


def merge_road(lead_in_m: float, ramp_m: float, after_m: float, lanes: int = 2, converge_m: float = 80.0,
               merge_m: float = 80.0, width_m: float = 4.0, speed_limit: float = 30.0) -> IndexedRoadNetwork:
    """highway-env's merge layout (merge-v0) on a longer straight road: ``lanes`` lanes, and on their right a ramp,
    lane index ``lanes`` of the first three segments, forbidden to the main road's traffic (MOBIL never moves there).
    Nodes "0"-"1": the lead-in (the ramp runs beside its last ``ramp_m`` metres, MERGE_GAP_M outside the next lane);
    "1"-"2": the ramp converges along a half sine (converge_m); "2"-"3": it is an acceleration lane beside the
    rightmost lane, with a dashed line between them (merge_m); "3"-"4": the road goes on (after_m). All [m]."""
    if not 0 < ramp_m <= lead_in_m:
        raise ValueError(f"the ramp must be 0 to {lead_in_m:g} m long, got {ramp_m:g}")
    net = IndexedRoadNetwork()
    ends = np.cumsum([0.0, lead_in_m, converge_m, merge_m, after_m])
    for k in range(4):
        for i in range(lanes):
            lt = line_types(i, lanes)
            if k == 2 and i == lanes - 1:
                lt = [lt[0], S]  # the acceleration lane joins here
            y = i * width_m
            net.add_lane(str(k), str(k + 1), StraightLane([ends[k], y], [ends[k + 1], y], width=width_m,
                                                         line_types=lt, speed_limit=speed_limit))
    y_join = lanes * width_m  # the ramp's centre once it has joined: one lane right of the rightmost
    y_ramp = y_join + MERGE_GAP_M
    ramp = dict(width=width_m, forbidden=True, speed_limit=speed_limit)
    net.add_lane("0", "1", StraightLane([ends[1] - ramp_m, y_ramp], [ends[1], y_ramp], line_types=[C, C], **ramp))
    # lateral offset from the mid line: (gap / 2) sin(pi s / converge_m + pi / 2), +gap/2 at its start, -gap/2 at its end
    net.add_lane("1", "2", SineLane([ends[1], y_join + MERGE_GAP_M / 2], [ends[2], y_join + MERGE_GAP_M / 2],
                                    MERGE_GAP_M / 2, np.pi / converge_m, np.pi / 2, line_types=[C, C], **ramp))
    net.add_lane("2", "3", StraightLane([ends[2], y_join], [ends[3], y_join], line_types=[N, C], **ramp))
    return net
