"""The slot table: one entry per driving task. The loop, scoring, recording, the CLI and the benchmark read it;
adding a task is a package (its vision slot) plus one entry here.

A slot is anything with ``reset()`` and ``step(frame, upstream) -> (estimate, debug)``; ``upstream`` holds the
estimates of the tasks named in the entry's ``upstream``. Perception packages implement it structurally and never
import ``drive``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Protocol

from percept.sensors import Frame, LandmarkMap, Pose2D, StereoRig

from . import privileged as priv
from .privileged import TruthFeed
from .odometry_scoring import OdometryScorer
from .scoring import LaneScorer, LongitudinalScorer, PedestrianScorer, ScoreContext


class Slot(Protocol):
    def reset(self) -> None: ...

    def step(self, frame: Frame, upstream: dict) -> tuple[object, object]: ...


@dataclass(frozen=True)
class SlotContext:
    """What a slot factory may use: the rig, the frame period [s], the landmark map (None without signs), the
    people model of the vision pedestrian slot ('sim', 'inria' or a file), the known start pose (where odometry
    starts; None = the origin); truth is for privileged slots only."""

    rig: StereoRig
    dt_s: float
    landmarks: LandmarkMap | None
    truth: TruthFeed
    detector: str = "sim"
    start_pose: Pose2D | None = None


@dataclass(frozen=True)
class Headline:
    """One metric the drive and eval tables show: a label with units, its key in the task's JSON group, a format."""

    label: str
    key: str
    fmt: str = "{:.3f}"


@dataclass(frozen=True)
class Task:
    """name: the CLI flag (--name) and the key of ``slots``; group: its JSON group; timing_key: its key in
    ``timing_ms`` and in ``percept bench``; privileged / vision: slot factories (vision None = not built yet);
    scorer: ScoreContext -> scorer; recorder: "module:function" of its part in ``percept.review`` (None = none);
    upstream: tasks whose estimates it reads; headline: metrics the tables show; help: one line for --help;
    bench_scenario: where ``percept bench`` times its vision slot; budget_ms: its per-frame budget [ms];
    bench_peer: frames -> (name, run(frame)), the stock way to do the same job, timed in the same run;
    bench_speedup: how many times faster than that peer the slot must be."""

    name: str
    group: str
    timing_key: str
    privileged: Callable[[SlotContext], Slot]
    scorer: Callable[[ScoreContext], object]
    vision: Callable[[SlotContext], Slot] | None = None
    recorder: str | Callable | None = None
    upstream: tuple[str, ...] = ()
    headline: tuple[Headline, ...] = ()
    help: str = ""
    bench_scenario: str = "highway"
    budget_ms: float | None = None
    bench_peer: Callable | None = None
    bench_speedup: float | None = None


def _longitudinal_slot(ctx: SlotContext) -> Slot:
    from percept.longitudinal.slot import LongitudinalSlot

    return LongitudinalSlot(ctx.rig, ctx.dt_s)


def _sgbm_peer(frames: list):
    from .bench import sgbm_full_frame

    return sgbm_full_frame(frames)


def _pedestrian_slot(ctx: SlotContext) -> Slot:
    from percept.detection import LinearModel, PedestrianSlot

    return PedestrianSlot(ctx.rig, ctx.dt_s, LinearModel.named(ctx.detector))


def _people_peer(frames: list):
    from .bench import people_detector_full_frame

    return people_detector_full_frame(frames)


def _odometry_slot(ctx: SlotContext) -> Slot:
    from percept.odometry import OdometrySlot

    return OdometrySlot(ctx.rig, ctx.dt_s, ctx.landmarks, ctx.start_pose or Pose2D(0.0, 0.0, 0.0))


def _lane_slot(ctx: SlotContext) -> Slot:
    from percept.lanes import LaneSlot

    return LaneSlot(ctx.rig, ctx.dt_s)


TASKS: tuple[Task, ...] = (
    Task("lateral", "lane", "lanes", priv.PrivilegedLateral, LaneScorer, vision=_lane_slot,
         recorder="percept.review.parts:lateral",
         headline=(Headline("lane offset RMSE [m]", "offset_rmse_m", "{:.4f}"),
                   Headline("lane heading RMSE [rad]", "heading_rmse_rad", "{:.4f}"),
                   Headline("lane curvature RMSE [1/m]", "curvature_rmse_1pm", "{:.5f}"),
                   Headline("centering RMS [m]", "centering_rms_m"), Headline("centering max [m]", "centering_max_m")),
         help="lane markings -> the ego path (steering)", bench_scenario="curves", budget_ms=3.0),
    Task("longitudinal", "longitudinal", "longitudinal", priv.PrivilegedLongitudinal,
         LongitudinalScorer, vision=_longitudinal_slot, recorder="percept.review.parts:longitudinal",
         upstream=("lateral",),
         headline=(Headline("range error (median)", "range_abs_rel_err", "{:.3f}"),
                   Headline("time gap mean [s]", "time_gap_mean_s", "{:.2f}"),
                   Headline("time gap min [s]", "time_gap_min_s", "{:.2f}"),
                   Headline("phantom brakes", "phantom_brakes", "{}")),
         help="the lead ahead (following, emergency braking)", budget_ms=3.0, bench_peer=_sgbm_peer,
         bench_speedup=15.0),
    Task("pedestrians", "pedestrians", "pedestrians", priv.PrivilegedPedestrians,
         PedestrianScorer, vision=_pedestrian_slot, recorder="percept.review.parts:pedestrians", upstream=("lateral",),
         headline=(Headline("recall", "recall", "{:.3f}"), Headline("false stops", "false_stops", "{}"),
                   Headline("verge brakes", "verge_brakes", "{}"),
                   Headline("brakes for no one", "brakes_for_no_one", "{}")),
         help="people in or stepping into the path (braking requests)", bench_scenario="crossing",
         bench_peer=_people_peer, bench_speedup=40.0),
    Task("odometry", "odometry", "odometry", priv.PrivilegedOdometry, OdometryScorer, vision=_odometry_slot,
         recorder="percept.review.parts:odometry", upstream=("longitudinal",),
         headline=(Headline("drift VO [%]", "drift_pct_vo", "{:.2f}"),
                   Headline("drift fused [%]", "drift_pct_fused", "{:.2f}"),
                   Headline("ATE with landmarks [m]", "ate_rmse_landmarks_m", "{:.2f}"),
                   Headline("inside 3 sigma", "consistency_3sigma", "{:.3f}")),
         help="where the car is, and its speed", bench_scenario="loop", budget_ms=5.0),
)


def task_order(tasks: tuple[Task, ...]) -> list[Task]:
    """The tasks in dependency order (upstream first, otherwise as listed); ValueError on a cycle or unknown name."""
    names = {t.name for t in tasks}
    for t in tasks:
        for u in t.upstream:
            if u not in names:
                raise ValueError(f"task {t.name} reads unknown task {u}")
    done: list[Task] = []
    pending = list(tasks)
    while pending:
        ready = [t for t in pending if all(u in {d.name for d in done} for u in t.upstream)]
        if not ready:
            raise ValueError(f"the tasks {[t.name for t in pending]} depend on each other in a cycle")
        done.append(ready[0])
        pending.remove(ready[0])
    return done
