"""Run metrics against ground truth (docs/design.md, "Scoring definitions"), one scorer per task returning its JSON
group (pedestrians in ``pedestrian_scoring``, neighbours in ``neighbours_scoring``, lane changes in
``lane_change_scoring``), plus the run-level safety counts. A metric that does not apply is None. The formulas live
in each task's ``metrics`` module (pure numpy), shared with the footage commands.

A scorer has ``update(estimate, debug, step)`` once per frame and ``result() -> dict``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from percept.lanes.metrics import centering, rmse_columns
from percept.longitudinal.metrics import range_abs_rel_err, range_abs_rel_err_by_bin, ttc_abs_err_s
from percept.sensors import ObjectKind
from percept.sensors.vehicle import EGO_WIDTH_M

from .privileged import InPath, Obstacle
from .rows import Rows

SAFETY_COUNTS = ("collisions", "pedestrian_collisions", "lane_departures", "unsafe_lane_changes")
"""The safety counts every run JSON has (integers); any of them makes a run unsafe (the last is the lane-change
scorer's ``lane_changes.unsafe``)."""
STOP_SPEED_MPS = 0.5
"""Below this speed the car has stopped [m/s]."""
HALTING_VEHICLE_MPS = 2.0
"""A vehicle in the path slower than this halts the car behind it: a stop behind it is not a false stop [m/s]."""
PHANTOM_DECEL_MPS2 = -3.0
"""A commanded deceleration below this with nothing in the path to justify it is a phantom brake [m/s²]."""
PHANTOM_MIN_SPEED_MPS = 2.0
"""Below this speed a hard deceleration is the end of a stop, not a phantom brake [m/s]."""
STEADY_REL_MPS = 0.5
"""The ego's and the lead's speeds match when within this of each other [m/s]."""
STEADY_S = 2.0
"""Following is steady once the speeds have matched for this long [s]; ``time_gap_steady_s`` averages the time gap
over those frames."""


@dataclass(frozen=True)
class ScoreContext:
    """What a scorer knows of its run besides the frames."""

    vision: bool  # the task's slot is a vision one (its estimates are scored)
    pedestrians: int  # how many pedestrians the scenario has
    crossing_pedestrians: int  # how many of them cross the road
    time_gap_setting_s: float  # the following law's time gap [s]
    # the rig's focal length times its baseline [px m]: one disparity pixel is Z^2 / (f b) of range at range Z
    # (None without a stereo rig)
    stereo_fb_px_m: float | None = None
    detector: str = "sim"  # the people model of the vision pedestrian slot


@dataclass(frozen=True)
class StepTruth:
    """One frame for the scorers: the truth and the commands sent."""

    truth: object  # the frame's GroundTruth
    ahead: list[InPath]  # ``path_objects`` of it: what stands in (or steps into) the true ego corridor
    in_path: Obstacle | None  # the true obstacle the ego must respect (None: nothing)
    accel_mps2: float  # the commanded acceleration [m/s²]
    steering_rad: float  # the commanded front-wheel angle [rad]
    change_side: int | None = None  # the side of the lane change (or its return, or a swerve) under way this frame,
    # +1 left, -1 right; 0: either (highway-env's MOBIL in the ego's place, whose side is not read); None: none

    @property
    def changing_lanes(self) -> bool:
        """A lane change is under way this frame."""
        return self.change_side is not None


def hard_braking(step: StepTruth) -> bool:
    """A commanded deceleration below PHANTOM_DECEL_MPS2 above PHANTOM_MIN_SPEED_MPS."""
    return step.accel_mps2 < PHANTOM_DECEL_MPS2 and step.truth.speed_mps >= PHANTOM_MIN_SPEED_MPS


@dataclass
class SafetyScorer:
    """Run-level counts: collisions, pedestrians hit, lane departures (a body edge crossing a lane boundary, unless a
    lane change is commanded and the boundary is the one it crosses: the far side of the lane left, or the near side
    of the lane it has come into)."""

    departures: int = 0  # times a body edge crossed a lane boundary that no commanded lane change crosses
    crashed: bool = False  # the ego hit something other than a pedestrian (those count in ped_hits)
    ped_hits: set = field(default_factory=set)  # ids of the pedestrians hit
    _over: int = 0  # the boundary a body edge is over this frame: +1 left, -1 right, 0 none
    _start_lane: int | None = None  # the true lane's id where the change under way began (None: no change)

    def update(self, step: StepTruth) -> None:
        gt = step.truth
        half = gt.lane.width_m / 2 - EGO_WIDTH_M / 2
        # a body edge over the left boundary: offset > w/2 - W/2; over the right one: offset < -(w/2 - W/2)
        over = 1 if gt.lane.offset_m > half else -1 if gt.lane.offset_m < -half else 0
        lane = gt.lane.lane_index[2]
        self._start_lane = (lane if self._start_lane is None else self._start_lane) if step.changing_lanes else None
        if over and not self._over and not self._crossed_by_change(step, over, lane):
            self.departures += 1
        self._over = over
        self.crashed |= gt.crashed and not gt.pedestrians_hit
        self.ped_hits.update(gt.pedestrians_hit)

    def _crossed_by_change(self, step: StepTruth, over: int, lane: int) -> bool:
        """Whether the boundary on side ``over`` of true lane ``lane`` is the one the commanded change crosses: on its
        side in the lane it began in, on the other side once the car is in the next one."""
        side = step.change_side
        if side is None or side == 0:  # no change, or highway-env's MOBIL: any boundary is its
            return side == 0
        return over == (side if lane == self._start_lane else -side)

    def result(self, unsafe_lane_changes: int = 0) -> dict:
        """The run's safety counts, under the names in ``SAFETY_COUNTS``; ``unsafe_lane_changes`` as the lane-change
        scorer counted them."""
        return dict(zip(SAFETY_COUNTS, (int(self.crashed), len(self.ped_hits), self.departures, unsafe_lane_changes)))


class LaneScorer:
    """Lane estimate errors (vision) and centering (always: the true offset from the lane centre, outside lane
    changes)."""

    def __init__(self, ctx: ScoreContext):
        self.ctx = ctx
        self.offsets_m = Rows(1)
        self.errors = Rows(3)  # offset [m], heading [rad], curvature [1/m]

    def update(self, path, debug, step: StepTruth) -> None:
        lane = step.truth.lane
        if not step.changing_lanes:  # centering is of keeping a lane, not of leaving it
            self.offsets_m.append((lane.offset_m,))
        est = path.lane if path is not None else None
        if self.ctx.vision and est is not None and est.valid:
            offset_err = est.offset_m - lane.offset_m
            if step.changing_lanes and lane.width_m > 0:
                # near the crossing the estimate and the truth may each name the lane on its own side of the boundary
                # for a frame or two: the estimate is judged against the true lane it describes, e -= round(e / w) w
                offset_err -= round(offset_err / lane.width_m) * lane.width_m
            self.errors.append((offset_err, est.heading_rad - lane.heading_rad, est.curvature_1pm - lane.curvature_1pm))

    def result(self) -> dict:
        return {**rmse_columns(self.errors.values()), **centering(self.offsets_m.values()[:, 0])}


class LongitudinalScorer:
    """Range / TTC errors of the lead (vision), time gaps behind a vehicle, phantom brakes."""

    def __init__(self, ctx: ScoreContext):
        self.ctx = ctx
        self.gaps_s = Rows(1)
        self.pairs = Rows(4)  # est range, true range, est ttc, true ttc
        self.steady_gaps_s = Rows(1)
        self._calm_since_s: float | None = None
        self.phantom_brakes = 0
        self._braking = False

    def update(self, lead, debug, step: StepTruth) -> None:
        gt, obstacle = step.truth, step.in_path
        # time gap to an in-path vehicle lead within 100 m, while moving
        following = (obstacle is not None and obstacle.kind is ObjectKind.VEHICLE and obstacle.gap_m < 100
                     and gt.speed_mps > 5)
        if following:
            self.gaps_s.append((obstacle.gap_m / gt.speed_mps,))
        # steady following: the speeds have matched within STEADY_REL_MPS for STEADY_S
        if following and abs(obstacle.speed_mps - gt.speed_mps) < STEADY_REL_MPS:
            self._calm_since_s = gt.time_s if self._calm_since_s is None else self._calm_since_s
            if gt.time_s - self._calm_since_s >= STEADY_S:
                self.steady_gaps_s.append((obstacle.gap_m / gt.speed_mps,))
        else:
            self._calm_since_s = None
        # phantom brake: a hard deceleration that begins, above a walking pace, with nothing in the path within the
        # stopping distance at 3 m/s^2 + 10 m (a braking that began for something may hold on to a standstill after
        # it has gone)
        reach = gt.speed_mps ** 2 / (2 * -PHANTOM_DECEL_MPS2) + 10.0
        justified = obstacle is not None and obstacle.gap_m <= reach
        braking = hard_braking(step)
        if braking and not self._braking and not justified:
            self.phantom_brakes += 1
        self._braking = braking
        if self.ctx.vision and lead is not None:
            truth = [p for p in step.ahead if p.now]
            if truth:
                t = min(truth, key=lambda p: p.gap_m)
                closing = gt.speed_mps - t.vx_mps
                true_ttc = t.obj.distance_m / closing if closing > 0 else np.nan
                est_ttc = lead.ttc_s if lead.ttc_s is not None else np.nan
                self.pairs.append((lead.range_m, t.obj.distance_m, est_ttc, true_ttc))

    def result(self) -> dict:
        g, steady, p = self.gaps_s.values()[:, 0], self.steady_gaps_s.values()[:, 0], self.pairs.values()
        scored = self.ctx.vision
        return {
            "range_abs_rel_err": range_abs_rel_err(p[:, 0], p[:, 1]) if scored else None,
            "range_abs_rel_err_by_bin": range_abs_rel_err_by_bin(p[:, 0], p[:, 1]) if scored else None,
            "ttc_abs_err_s": ttc_abs_err_s(p[:, 2], p[:, 3]) if scored else None,
            "time_gap_mean_s": float(np.mean(g)) if len(g) else None,
            "time_gap_min_s": float(np.min(g)) if len(g) else None,
            "time_gap_steady_s": float(np.mean(steady)) if len(steady) else None,
            "time_gap_setting_s": self.ctx.time_gap_setting_s,
            "phantom_brakes": self.phantom_brakes,
        }
