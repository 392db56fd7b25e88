"""What the longitudinal laws act on: the nearest of the lead, the braking request and a neighbour cutting in, as a
bumper gap."""

from __future__ import annotations

from dataclasses import dataclass

from percept.sensors import BrakingRequest, Lead, Neighbours, ObjectKind, Zone
from percept.sensors.vehicle import bumper_gap_m


@dataclass(frozen=True)
class Target:
    """What a longitudinal law acts on."""

    gap_m: float  # free distance from the front bumper [m]
    closing_mps: float  # how fast the gap shrinks, -range rate [m/s]
    kind: ObjectKind  # what is there
    source: str  # the record it comes from: "lead", "request", "cut-in" or "target lane"

    @property
    def is_pedestrian(self) -> bool:
        return self.kind is ObjectKind.PEDESTRIAN


def nearer(*targets: Target | None) -> Target | None:
    """The nearest of ``targets`` (None where none is given)."""
    return min((t for t in targets if t is not None), key=lambda t: t.gap_m, default=None)


def in_target_lane(neighbours: Neighbours | None, into_lane: int) -> Target | None:
    """While the car changes into the lane ``into_lane`` (+1 left, -1 right; 0 none), the nearest neighbour ahead in
    that lane; None otherwise."""
    ahead = neighbours.nearest(into_lane, Zone.AHEAD) if into_lane and neighbours is not None else None
    return None if ahead is None else Target(ahead.gap_m, -ahead.rel_speed_mps, ObjectKind.VEHICLE, "target lane")


def nearest_target(lead: Lead | None, request: BrakingRequest | None,
                   neighbours: Neighbours | None = None) -> Target | None:
    """The nearest of the lead (longitudinal slot), the braking request (pedestrian slot) and the neighbour flagged
    as cutting in (neighbours slot); None when there is none. During a lane change the agent adds
    ``in_target_lane`` with ``nearer``."""
    cands = []
    cut_in = neighbours.cutting_in() if neighbours is not None else None
    if cut_in is not None:
        cands.append(Target(cut_in.gap_m, -cut_in.rel_speed_mps, ObjectKind.VEHICLE, "cut-in"))
    if lead is not None:
        cands.append(Target(bumper_gap_m(lead.range_m), -lead.range_rate_mps, lead.kind, "lead"))
    if BrakingRequest.asking(request) is not None:
        cands.append(Target(bumper_gap_m(request.stop_before_m), -request.range_rate_mps, request.kind, "request"))
    return nearer(*cands)
