"""The slot table: one entry per driving task. The loop, the agent, scoring, recording, the CLI's per-task options,
evaluation's resume keys and reports and the benchmark all read it; adding a task is a package (its vision slot) plus
one entry here.

A task has one name wherever a user meets it: its CLI option (``--lanes vision``), its JSON group, its
``timing_ms`` key, its recording part and its ``percept bench`` stage. Task names appear as string literals only in
this module; the same words elsewhere name other things: the footage commands ``percept lanes`` and ``percept
odometry`` (and their overlay files' suffix), and the TuSimple format's ``"lanes"`` key.

A slot is anything with ``reset()`` and ``step(frame, upstream) -> (estimate, debug)``; ``upstream`` maps each
record type the entry ``reads`` to the estimate of the task that ``provides`` it, so a slot asks for
``upstream[EgoPath]`` and never for another task by name, and the agent finds what steers, what brakes and what
measures speed by the record each task provides (docs/design.md, "Agent and slots").
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib import import_module
from typing import TYPE_CHECKING, Callable, Protocol

from percept.sensors.poses import Pose2D
from percept.sensors.records import BrakingRequest, EgoPath, LandmarkMap, Lead, Neighbours, PoseEstimate

if TYPE_CHECKING:
    from percept.sensors import Frame, StereoRig

    from .privileged import TruthFeed
    from .scoring import ScoreContext


@dataclass(frozen=True)
class lazy:  # noqa: N801 - used like a function in the table
    """A callable that imports ``"module:attribute"`` when called and calls it: the table names its slots and
    scorers without importing them, so that reading it (``--help`` does) stays cheap; it pickles (Ray, workers)."""

    ref: str  # "module:attribute"

    def __call__(self, *args, **kwargs):
        module, attr = self.ref.split(":")
        return getattr(import_module(module), attr)(*args, **kwargs)


class Slot(Protocol):
    """What the agent steps: a task's estimator, vision or privileged."""

    def reset(self) -> None: ...

    def step(self, frame: Frame, upstream: dict) -> tuple[object, object]: ...


@dataclass(frozen=True)
class SlotContext:
    """What a slot factory may use; truth is for privileged slots only."""

    rig: StereoRig  # the forward stereo rig
    dt_s: float  # frame period [s]
    landmarks: LandmarkMap | None  # the mapped landmarks (None: a road without signs)
    truth: "TruthFeed"  # this frame's ground truth, for privileged slots
    detector: str = "sim"  # people model of the vision pedestrian slot: "sim", "inria" or a model file
    start_pose: Pose2D | None = None  # the known start pose, where odometry starts (None: the origin)
    rear_rig: StereoRig | None = None  # the rear-facing stereo rig (None: the car has none)


@dataclass(frozen=True)
class Headline:
    """One metric the drive and eval tables show."""

    label: str  # what the tables print, with units
    key: str  # its key in the task's JSON group
    fmt: str = "{:.3f}"  # how the tables format it


@dataclass(frozen=True)
class Count:
    """A count of events in the task's JSON group that evaluation sums per scenario and condition."""

    key: str  # its key in the task's JSON group (an integer per run)
    label: str  # what the reports print
    listed: bool = False  # list the runs that have any under "Runs to look at" (worth a look, not failing)


@dataclass(frozen=True)
class Outcome:
    """Events that each end well or not, as a list of booleans in the task's JSON group (one per event)."""

    key: str  # its key in the task's JSON group
    label: str  # what the tables print beside "N of M"
    missed: str  # the name of the count of those that did not end well (summed like a Count)


@dataclass(frozen=True)
class Task:
    """One driving task: its name, where its estimate comes from, how it is scored, recorded and benchmarked."""

    name: str  # the one name: --NAME, the JSON group, the timing_ms key, the recording part, the bench stage
    provides: type  # the record its slots return (or None in its place); the agent and readers find it by this type
    privileged: Callable[[SlotContext], Slot]  # the slot on ground truth, the baseline
    scorer: Callable[[ScoreContext], object]  # ScoreContext -> scorer with update(...) and result() -> JSON group
    vision: Callable[[SlotContext], Slot] | None = None  # the slot on the cameras (None: not built yet)
    recorder: str | Callable | None = None  # "module:attribute" of its recording part in percept.review (None: none)
    reads: tuple[type, ...] = ()  # record types of other tasks its slot reads, as upstream[type]
    headline: tuple[Headline, ...] = ()  # metrics the drive and eval tables show
    help: str = ""  # what it computes, one line for --help
    bench_scenario: str = "highway"  # where percept bench times its vision slot
    budget_ms: float | None = None  # its per-frame budget in percept bench [ms] (None: none of its own)
    bench_peer: Callable | None = None  # frames -> (name, run(frame)): the stock way to do its job, timed beside it
    bench_speedup: float | None = None  # how many times faster than that peer the slot must be (None: no target)
    slot_options: tuple[str, ...] = ()  # DriveConfig fields its vision slot reads (they change its results)
    counts: tuple[Count, ...] = ()  # safety-relevant counts that evaluation sums
    outcome: Outcome | None = None  # events that end well or not (evaluation tallies them)
    higher_is_better: tuple[str, ...] = ()  # keys of its group where more is better (reports' p95 and worst)
    eval_plots: Callable | None = None  # (task name, plan, results) -> {file name: BGR image}: its own plots


def _longitudinal_slot(ctx: SlotContext) -> Slot:
    from percept.longitudinal.slot import LongitudinalSlot

    return LongitudinalSlot(ctx.rig, ctx.dt_s)


def _pedestrian_slot(ctx: SlotContext) -> Slot:
    from percept.detection import LinearModel, PedestrianSlot

    return PedestrianSlot(ctx.rig, ctx.dt_s, LinearModel.named(ctx.detector))


def _odometry_slot(ctx: SlotContext) -> Slot:
    from percept.odometry import OdometrySlot

    return OdometrySlot(ctx.rig, ctx.dt_s, ctx.landmarks, ctx.start_pose or Pose2D(0.0, 0.0, 0.0))


def _neighbour_slot(ctx: SlotContext) -> Slot:
    from percept.neighbours import NeighbourSlot
    return NeighbourSlot(ctx.rig, ctx.rear_rig, ctx.dt_s)


def _lane_slot(ctx: SlotContext) -> Slot:
    from percept.lanes import LaneSlot

    return LaneSlot(ctx.rig, ctx.dt_s)


TASKS: tuple[Task, ...] = (
    Task("lanes", EgoPath, lazy("percept.drive.privileged:PrivilegedLanes"),
         lazy("percept.drive.scoring:LaneScorer"), vision=_lane_slot,
         recorder="percept.review.parts.lanes:PART",
         headline=(Headline("offset RMSE [m]", "offset_rmse_m", "{:.4f}"),
                   Headline("heading RMSE [rad]", "heading_rmse_rad", "{:.4f}"),
                   Headline("curvature RMSE [1/m]", "curvature_rmse_1pm", "{:.5f}"),
                   Headline("centering RMS [m]", "centering_rms_m"), Headline("centering max [m]", "centering_max_m")),
         help="lane markings -> the ego path (steering)", bench_scenario="curves", budget_ms=3.0,
         bench_peer=lazy("percept.bench.peers:lane_fit_full_frame")),
    Task("longitudinal", Lead, lazy("percept.drive.privileged:PrivilegedLongitudinal"),
         lazy("percept.drive.scoring:LongitudinalScorer"), vision=_longitudinal_slot,
         recorder="percept.review.parts.longitudinal:PART", reads=(EgoPath,),
         headline=(Headline("range error (median)", "range_abs_rel_err", "{:.3f}"),
                   Headline("time gap mean [s]", "time_gap_mean_s", "{:.2f}"),
                   Headline("time gap min [s]", "time_gap_min_s", "{:.2f}"),
                   Headline("phantom brakes", "phantom_brakes", "{}")),
         help="the lead ahead (following, emergency braking)", budget_ms=3.0,
         bench_peer=lazy("percept.bench.peers:sgbm_full_frame"), bench_speedup=15.0,
         counts=(Count("phantom_brakes", "phantom brakes"),),
         higher_is_better=("time_gap_mean_s", "time_gap_min_s", "time_gap_steady_s"),
         eval_plots=lazy("percept.evaluate.plots:range_error_by_range")),
    Task("pedestrians", BrakingRequest, lazy("percept.drive.privileged:PrivilegedPedestrians"),
         lazy("percept.drive.pedestrian_scoring:PedestrianScorer"), vision=_pedestrian_slot,
         recorder="percept.review.parts.pedestrians:PART", reads=(EgoPath,),
         headline=(Headline("recall", "recall", "{:.3f}"), Headline("false stops", "false_stops", "{}"),
                   Headline("verge brakes", "verge_brakes", "{}"),
                   Headline("brakes for no one", "brakes_for_no_one", "{}")),
         help="people in or stepping into the path (braking requests)", bench_scenario="crossing",
         bench_peer=lazy("percept.bench.peers:people_detector_full_frame"), bench_speedup=40.0,
         slot_options=("detector",), outcome=Outcome("stops", "crossings stopped for", "missed_stops"),
         counts=(Count("false_stops", "false stops", listed=True),
                 Count("brakes_for_no_one", "brakes for no one", listed=True)),
         higher_is_better=("recall", "precision", "first_detection_range_m")),
    Task("odometry", PoseEstimate, lazy("percept.drive.privileged:PrivilegedOdometry"),
         lazy("percept.drive.odometry_scoring:OdometryScorer"), vision=_odometry_slot,
         recorder="percept.review.parts.odometry:PART", reads=(Lead,),
         headline=(Headline("drift VO [%]", "drift_pct_vo", "{:.2f}"),
                   Headline("drift fused [%]", "drift_pct_fused", "{:.2f}"),
                   Headline("ATE with landmarks [m]", "ate_rmse_landmarks_m", "{:.2f}"),
                   Headline("inside 3 sigma", "consistency_3sigma", "{:.3f}")),
         help="where the car is, and its speed", bench_scenario="loop", budget_ms=5.0,
         higher_is_better=("consistency_3sigma", "consistency_3sigma_fused", "landmark_fixes", "landmark_sightings",
                           "path_length_m"),
         eval_plots=lazy("percept.evaluate.plots:worst_trajectories")),
    Task("neighbours", Neighbours, lazy("percept.drive.neighbours_truth:PrivilegedNeighbours"),
         lazy("percept.drive.neighbours_scoring:NeighbourScorer"), vision=_neighbour_slot,
         recorder="percept.review.parts.neighbours:PART", reads=(EgoPath,),
         headline=(Headline("recall ahead", "recall_ahead", "{:.3f}"),
                   Headline("recall behind", "recall_behind", "{:.3f}"),
                   Headline("beside absent [frames]", "beside_absent_frames", "{}"),
                   Headline("gap error ahead (median)", "gap_abs_rel_err_ahead", "{:.3f}"),
                   Headline("cut-in lead min [s]", "cut_in_warning_lead_s_min", "{:.2f}")),
         help="vehicles ahead, beside and behind in the ego and next lanes (cut-ins)", bench_scenario="dense",
         budget_ms=8.0,
         bench_peer=lazy("percept.bench.peers:sgbm_both_rigs"),
         counts=(Count("beside_absent_frames", "frames a vehicle beside was absent", listed=True),
                 Count("cut_ins_missed", "cut-ins not warned", listed=True)),
         higher_is_better=("recall_ahead", "recall_beside", "recall_behind", "lane_accuracy",
                           "cut_in_warning_lead_s_min")),
)


def task_order(tasks: tuple[Task, ...]) -> list[Task]:
    """The tasks in dependency order (a task after those providing what it reads, otherwise as listed); ValueError
    on a repeated name or record, a record no task provides, or a cycle."""
    providers = {}
    for t in tasks:
        if t.name in {p.name for p in providers.values()}:
            raise ValueError(f"two tasks are named {t.name}")
        if t.provides in providers:
            raise ValueError(f"tasks {providers[t.provides].name} and {t.name} both provide {t.provides.__name__}")
        providers[t.provides] = t
    for t in tasks:
        for rec in t.reads:
            if rec not in providers:
                raise ValueError(f"task {t.name} reads {rec.__name__}, which no task provides")
    done: list[Task] = []
    pending = list(tasks)
    while pending:
        ready = [t for t in pending if all(providers[r] in done for r in t.reads)]
        if not ready:
            raise ValueError(f"the tasks {[t.name for t in pending]} depend on each other in a cycle")
        done.append(ready[0])
        pending.remove(ready[0])
    return done


def upstream_of(task: Task, estimates: dict) -> dict:
    """What ``task``'s slot reads: each record type in ``task.reads`` -> its estimate, from ``estimates`` (record
    type -> this frame's estimate of the task that provides it)."""
    return {rec: estimates[rec] for rec in task.reads}
