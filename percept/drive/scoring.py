"""Run metrics against ground truth (DESIGN.md, "Scoring definitions"). A metric that does not apply is None."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .privileged import EGO_HALF_WIDTH_M, Obstacle

STOP_SPEED_MPS = 0.5


@dataclass
class RunScorer:
    """Accumulates per-frame truth and commands; ``result()`` gives the JSON-ready metrics."""

    offsets_m: list = field(default_factory=list)
    gaps_s: list = field(default_factory=list)
    departures: int = 0
    _outside: bool = False
    crashed: bool = False
    ped_hits: set = field(default_factory=set)
    crossing_seen: dict = field(default_factory=dict)
    crossing_stopped: dict = field(default_factory=dict)
    false_stops: int = 0
    _stopped: bool = False

    def update(self, gt, obstacle: Obstacle | None, hit_pedestrians: list[int]) -> None:
        lane = gt.lane
        self.offsets_m.append(lane.offset_m)
        # a departure: a body edge crosses a lane boundary (no lane changes are commanded)
        outside = abs(lane.offset_m) + EGO_HALF_WIDTH_M > lane.width_m / 2
        if outside and not self._outside:
            self.departures += 1
        self._outside = outside
        self.crashed |= gt.crashed and not hit_pedestrians
        self.ped_hits.update(hit_pedestrians)
        # time gap to an in-path vehicle lead within 100 m, while moving
        if obstacle is not None and obstacle.kind == "vehicle" and obstacle.gap_m < 100 and gt.speed_mps > 5:
            self.gaps_s.append(obstacle.gap_m / gt.speed_mps)
        # pedestrians: a crossing person counts as stopped for if the ego halts while it is within 40 m ahead
        stopped = gt.speed_mps < STOP_SPEED_MPS
        near_crossing = False
        for o in gt.objects:
            if o.kind == "pedestrian" and o.crossing and 0 < o.position_m[0] < 40:
                self.crossing_seen.setdefault(o.obj_id, True)
                near_crossing = True
                if stopped:
                    self.crossing_stopped[o.obj_id] = True
        # a stop with no crossing pedestrian near is a false stop (e.g. for a roadside one), unless a vehicle halts us
        if stopped and not self._stopped and not near_crossing and not (obstacle and obstacle.kind == "vehicle"):
            self.false_stops += 1
        self._stopped = stopped

    def result(self, has_crossing: bool) -> dict:
        off = np.abs(np.asarray(self.offsets_m))
        stops = [bool(self.crossing_stopped.get(k, False)) for k in sorted(self.crossing_seen)]
        return {
            "collisions": int(self.crashed),
            "pedestrian_collisions": len(self.ped_hits),
            "lane_departures": self.departures,
            "centering_rms_m": float(np.sqrt(np.mean(off ** 2))) if len(off) else None,
            "centering_max_m": float(off.max()) if len(off) else None,
            "time_gap_mean_s": float(np.mean(self.gaps_s)) if self.gaps_s else None,
            "time_gap_min_s": float(np.min(self.gaps_s)) if self.gaps_s else None,
            # steady state: the last quarter of the frames that had a lead
            "time_gap_steady_s": float(np.mean(self.gaps_s[-max(len(self.gaps_s) // 4, 1):])) if self.gaps_s else None,
            "stops": stops if has_crossing else None,
            "false_stops": self.false_stops,
        }


