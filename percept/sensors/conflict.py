"""When a person ahead conflicts with the ego path: in the corridor now, or walking into it before the ego gets
there. One rule for the privileged slot (on ground truth) and the vision slot (on its tracks).

Vehicle frame (x forward, y left) [m]; the corridor is the ego's body width plus a margin, centred on the path.
"""

from __future__ import annotations

from dataclasses import dataclass

from .vehicle import EGO_WIDTH_M

PERSON_HALF_M = 0.3
"""Half a person's width [m]."""
CORRIDOR_MARGIN_M = 0.4
"""Clearance kept either side of the ego's body [m]."""
PERSON_CORRIDOR_HALF_M = EGO_WIDTH_M / 2 + CORRIDOR_MARGIN_M + PERSON_HALF_M
"""A person's centre closer than this to the path's centre line touches the ego's corridor [m]."""
PERSON_STOP_MARGIN_M = 4.0
"""The car stops this far short of a person in its path (front bumper to person) [m]."""


@dataclass(frozen=True)
class Conflict:
    """now: the person is in the corridor; entering: walking across the carriageway towards it (within a lane of
    it, or crossing its centre line before the ego arrives, or inside it by then). A person walking away from the
    corridor has left it."""

    now: bool
    entering: bool

    @property
    def any(self) -> bool:
        return self.now or self.entering


def person_conflict(x_m: float, y_m: float, vy_mps: float, centre_y_m: float, lane_width_m: float,
                    ego_speed_mps: float, horizon_s: float = 4.0, min_walk_mps: float = 0.2) -> Conflict:
    """A person at (x_m, y_m) walking sideways at vy_mps, with the path's centre at centre_y_m at that distance."""
    now = abs(y_m - centre_y_m) < PERSON_CORRIDOR_HALF_M
    if now or abs(vy_mps) <= min_walk_mps or x_m <= 0:
        return Conflict(now, False)
    # where the person will be when the ego gets there (or at the horizon): y(t) = y + vy t, t = x / v
    t = min(horizon_s, x_m / max(ego_speed_mps, 1.0))
    y_future = y_m + vy_mps * t
    d_now, d_future = y_m - centre_y_m, y_future - centre_y_m
    # walking towards the corridor (d vy < 0) within a lane of it, inside it by then, or across it by then
    towards = d_now * vy_mps < 0
    entering = ((towards and abs(d_now) < PERSON_CORRIDOR_HALF_M + lane_width_m)
                or abs(d_future) < PERSON_CORRIDOR_HALF_M or d_now * d_future < 0)
    return Conflict(False, entering)
