"""Progress and lane changes against ground truth: the run JSON's ``progress``, ``lane_changes`` and ``evasive``
groups.

Progress is the mean true speed, its ratio to the set speed, and the distance driven. A lane change is started,
completed or aborted as the lane-change law's debug record says (null where no law commands the car: lane changes
off, or highway-env's MOBIL driving it). A change is **unsafe** when, on the frame the ego's true lane changes, the
new follower would have to brake harder than ``UNSAFE_BRAKING_MPS2`` by IDM with highway-env's own ``IDMVehicle``
parameters (``control.idm_accel``; the follower taken to want its own speed, so that only the ego's arrival brakes
it) to keep its safe gap, or the bumper gap ahead or behind in the new lane is under ``UNSAFE_TIME_GAP_S`` at the
ego's speed, or a car is beside the ego in it. Peak lateral acceleration and jerk are
the true ones (the IMU's lateral axis without noise, less the lane's own centripetal v^2 kappa) over the frames of
a commanded change, swerves left out. Evasive manoeuvres (``evasive``) are the evasion law's swerves and its full
braking where no lane was free, each with its outcome: whether the ego hit anything within ``EVASIVE_WINDOW_S``.
"""

from __future__ import annotations

from percept.control import EVASIVE_EVENTS, Phase, idm_accel
from percept.sensors import Zone

from .neighbours_truth import truth_neighbours

UNSAFE_BRAKING_MPS2 = 2.0
"""A change that makes its new follower brake harder than this is unsafe [m/s²]."""
UNSAFE_TIME_GAP_S = 0.5
"""A change that leaves a gap ahead or behind shorter than this at the ego's speed is unsafe [s]."""
JUDGED_WITHIN_M = 300.0
"""The new follower and leader judged at a crossing are the nearest true cars within this bumper gap, well beyond what
the rigs see, so that a fast car coming from out of their view counts [m]."""
EVASIVE_WINDOW_S = 5.0
"""An evasive manoeuvre failed when the ego hits something within this long of its start [s]."""


class ProgressScorer:
    """Mean speed, its ratio to the set speed and the distance driven."""

    def __init__(self, set_speed_mps: float, dt_s: float):
        self.set_speed, self.dt = set_speed_mps, dt_s
        self.speeds: list[float] = []

    def update(self, gt) -> None:
        self.speeds.append(float(gt.speed_mps))

    def result(self) -> dict:
        if not self.speeds:
            return {"mean_speed_mps": None, "set_speed_ratio": None, "distance_m": None}
        mean = sum(self.speeds) / len(self.speeds)
        return {"mean_speed_mps": mean, "set_speed_ratio": mean / self.set_speed if self.set_speed > 0 else None,
                "distance_m": sum(self.speeds) * self.dt}


class LaneChangeScorer:
    """Lane changes started, completed, aborted and unsafe, and the peak lateral acceleration and jerk in them."""

    def __init__(self, dt_s: float, commanded: bool = True):
        """dt_s: the frame period [s]; commanded: the lane-change law drives the car's changes (its counts apply)."""
        self.dt, self.commanded = dt_s, commanded
        self.counts = {"started": 0, "completed": 0, "aborted": 0, "unsafe": 0}
        self.crossings: list[dict] = []  # per boundary crossing of a change: the new follower's braking, the gaps
        self.peak_accel = None  # [m/s²]
        self.peak_jerk = None  # [m/s³]
        self._lane = None  # the ego's true lane id on the previous frame
        self._accel = None  # the lateral acceleration on the previous frame of a change [m/s²]
        self.evasive: list[dict] = []  # per evasive manoeuvre: when, what, and whether the ego hit anything

    def update(self, gt, debug) -> None:
        """One frame: ``gt`` the ground truth, ``debug`` the lane-change law's record (None: lane changes off)."""
        lane = gt.lane.lane_index[2]
        changing = debug is not None and debug.phase not in (Phase.KEEP, Phase.EVADE)
        if debug is not None and debug.event in self.counts:
            self.counts[debug.event] += 1
        self._evasive(gt, debug)
        if self._lane is not None and lane != self._lane:
            self._judge_crossing(gt)
        self._lane = lane
        # the manoeuvre's own lateral acceleration: the IMU's less the lane's centripetal v^2 kappa
        accel = float(gt.imu.accel_mps2[1]) - gt.speed_mps ** 2 * gt.lane.curvature_1pm
        if changing:
            self.peak_accel = max(self.peak_accel or 0.0, abs(accel))
            if self._accel is not None:
                jerk = abs(accel - self._accel) / self.dt
                self.peak_jerk = max(self.peak_jerk or 0.0, jerk)
        self._accel = accel if changing else None

    def _evasive(self, gt, debug) -> None:
        """Note an evasive manoeuvre's start, and a collision within ``EVASIVE_WINDOW_S`` of it."""
        if debug is not None and debug.event in EVASIVE_EVENTS:
            self.evasive.append({"time_s": round(gt.time_s, 3), "kind": debug.event, "side": debug.side,
                                 "collision": False})
        for e in self.evasive:
            if gt.crashed and gt.time_s - e["time_s"] <= EVASIVE_WINDOW_S:
                e["collision"] = True

    def evasive_result(self) -> dict:
        """The run JSON's ``evasive`` group: count, swerves, full brakings and those that ended in a collision (null
        where no law commands the car; collisions null where there was no evasive manoeuvre)."""
        if not self.commanded:
            return {"count": None, "swerves": None, "full_braking": None, "collisions": None, "manoeuvres": []}
        kinds = [e["kind"] for e in self.evasive]
        return {"count": len(kinds), "swerves": kinds.count("swerve"), "full_braking": kinds.count("full braking"),
                "collisions": sum(e["collision"] for e in self.evasive) if kinds else None,
                "manoeuvres": self.evasive}

    def _judge_crossing(self, gt) -> None:
        """The new lane's follower and gaps on the frame the ego's centre entered it."""
        v = gt.speed_mps
        around = truth_neighbours(gt, JUDGED_WITHIN_M, JUDGED_WITHIN_M)
        ahead, behind = around.nearest(0, Zone.AHEAD), around.nearest(0, Zone.BEHIND)
        # the follower wants its own speed: only the ego's arrival brakes it
        vf = v + behind.rel_speed_mps if behind is not None else 0.0
        braking = None if behind is None else idm_accel(vf, vf, behind.gap_m, behind.rel_speed_mps)
        short = [g for g in (ahead, behind) if g is not None and g.gap_m < UNSAFE_TIME_GAP_S * v]
        beside = around.nearest(0, Zone.BESIDE) is not None
        unsafe = bool(short) or beside or (braking is not None and braking < -UNSAFE_BRAKING_MPS2)
        self.counts["unsafe"] += int(unsafe)
        self.crossings.append({"time_s": round(gt.time_s, 3), "follower_braking_mps2": braking,
                               "gap_ahead_m": None if ahead is None else ahead.gap_m,
                               "gap_behind_m": None if behind is None else behind.gap_m, "unsafe": unsafe})

    def result(self) -> dict:
        law = {k: self.counts[k] if self.commanded else None for k in ("started", "completed", "aborted")}
        return {**law, "unsafe": self.counts["unsafe"], "peak_lateral_accel_mps2": self.peak_accel,
                "peak_lateral_jerk_mps3": self.peak_jerk, "crossings": self.crossings}
