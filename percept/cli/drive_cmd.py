"""`percept drive`: one closed-loop run, scored against ground truth and recorded to Rerun."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Optional

import typer
from rich.markup import escape
from rich.table import Table

from . import options as opt
from .common import check_outputs, console, fail, fmt, on_interrupt, progress_bar, write_error, write_json


def drive(
    scenario: opt.Scenario = "highway",
    seed: opt.Seed = 0,
    condition: opt.Condition = "clear",
    duration: opt.Duration = None,
    sources: dict = None,
    detector: opt.Detector = "sim",
    privileged: opt.Privileged = False,
    rear: opt.Rear = None,
    lane_changes: opt.LaneChanges = "on",
    record: Annotated[Optional[Path], typer.Option(
        "--record", dir_okay=False, help="Rerun recording path (default runs/<scenario>-<condition>-<seed>.rrd); "
                                         "an interrupted run is kept beside it as RUN.partial.rrd.")] = None,
    no_record: Annotated[bool, opt.flag("--no-record", help="Do not write a Rerun recording.")] = False,
    camera_hz: Annotated[float, typer.Option("--camera-hz", help="Camera images stored per simulated second in "
                                             "the recording, 0.01 to 1000 (15 = every frame).")] = 5.0,
    camera_quality: Annotated[int, typer.Option("--camera-quality", help="JPEG quality of the recorded camera "
                                                "images, 1 to 100.")] = 70,
    camera_scale: Annotated[float, typer.Option("--camera-scale", help="Recorded image size relative to the "
                                                "camera's, 0.1 to 1.")] = 0.75,
    json_path: opt.JsonOut = None,
):
    """Drive a scenario in closed loop from the cameras, score it against ground truth and record it to Rerun."""
    from percept.detection import LinearModel
    from percept.drive import DriveConfig, run_drive
    from percept.review import partial_path
    from percept.sims import WorldConfig

    opt.check_number("--seed", seed, 0, opt.MAX_SEED)
    opt.check_number("--duration", duration, 1e-3, opt.MAX_DURATION_S)
    try:
        cfg = DriveConfig(WorldConfig(scenario=scenario, seed=seed, condition=condition), duration,
                          opt.slot_sources(sources, privileged), detector=detector, rear=rear,
                          lane_changes=opt.lane_changes_on(lane_changes))
    except ValueError as e:
        fail(str(e))
    if no_record and record is not None:
        fail("--record and --no-record contradict each other; give one")
    if record is not None and record.suffix != ".rrd":
        fail(f"--record {record}: a Rerun recording is a .rrd file; give a path ending in .rrd")
    rec_path = None if no_record else (record or Path("runs") / f"{scenario}-{cfg.world.condition.value}-{seed}.rrd")
    recording = Recording(rec_path, cfg, camera_hz, camera_quality, camera_scale)  # checks its options
    check_outputs([rec_path, rec_path and partial_path(rec_path), json_path], [LinearModel.file_of(detector)])
    with progress_bar() as bar:
        task = bar.add_task(f"driving {scenario}/{cfg.world.condition.value}/seed {seed}", total=None)
        try:
            # frames are rendered when a slot or the recording needs them
            result = run_drive(cfg, recorder_factory=recording.open if rec_path else None,
                               progress=lambda i, n: bar.update(task, completed=i, total=n),
                               render=rec_path is not None or cfg.needs_cameras)
        except BaseException:
            recording.close(complete=False)
            raise
    recording.close()
    write_json(json_path, result)
    console.print(summary_table(cfg, result))
    if rec_path:
        console.print(f"recording: {rec_path}  (open it with `percept view {rec_path}`)")


class Recording:
    """The run's recording: options checked before the run, the recorder made once the world exists
    (``open``), closed complete or partial; says what Ctrl-C keeps."""

    def __init__(self, path: Optional[Path], cfg, camera_hz: float, quality: int, scale: float):
        from percept.review import RecordOptions

        opt.check_number("--camera-hz", camera_hz, 0.01, 1000)
        opt.check_number("--camera-quality", quality, 1, 100)
        opt.check_number("--camera-scale", scale, 0.1, 1)
        self.path, self.cfg, self.recorder = path, cfg, None
        self.options = RecordOptions(camera_hz, quality, scale)
        on_interrupt(self.kept)

    def kept(self) -> str:
        """What an interrupted run leaves: the partial recording, if one was made."""
        where = self.recorder and self.recorder.closed_as
        if not where:
            return "nothing was written or replaced"
        return f"{'the finished recording is' if where == self.path else 'the recording so far is kept as'} " \
               f"{where}; no JSON was written or replaced"

    def open(self, world):
        """The recorder of ``world``'s run (``run_drive``'s recorder factory)."""
        from percept.review import RunRecorder

        # the run's length, so that the recorder can check its disk holds it before anything is written
        duration_s = self.cfg.duration_s if self.cfg.duration_s is not None else world.scenario.duration_s
        # the rear rig, where the world has one (WorldConfig.rear_rig; None: none)
        self.recorder = RunRecorder(self.path, world.cfg.rig, world.road_geometry.lane_lines, self.cfg.tasks,
                                    self.options, duration_s=duration_s, rear_rig=world.cfg.rear_rig)
        return self.recorder

    def close(self, complete: bool = True) -> None:
        """Move the recording into place; a one-line error if the disk refuses a finished one. An interrupted or
        failed run's partial recording is best effort: the interrupt or error itself is what gets reported."""
        if self.recorder is None:
            return
        try:
            self.recorder.close(complete=complete)
        except OSError as e:
            if complete:
                fail(write_error(self.path, e))


def summary_table(cfg, result: dict) -> Table:
    """The run's safety counts and every task's headline metrics (n/a where one does not apply)."""
    t = Table(title=f"{result['scenario']} / {result['condition']} / seed {result['seed']}: {result['frames']} "
                    f"frames, {result['duration_s']:.1f} s, realtime x{result['realtime_factor']:.2f}")
    for col, just in (("task", "left"), ("metric", "left"), ("value", "right")):
        t.add_column(col, justify=just)
    from percept.drive.scoring import SAFETY_COUNTS

    for k in SAFETY_COUNTS:
        t.add_row("run", k.replace("_", " "), fmt(result[k], "{}"))
    t.add_row("progress", "mean speed [m/s]", fmt(result["progress"]["mean_speed_mps"], "{:.2f}"))
    t.add_row("", "of the set speed", fmt(result["progress"]["set_speed_ratio"], "{:.3f}"))
    changes = result["lane_changes"]
    t.add_row("lane changes", "started / completed / aborted / unsafe",
              " / ".join(fmt(changes[k], "{}") for k in ("started", "completed", "aborted", "unsafe"))
              if result["lane_changes_on"] else "off")
    evasive = result["evasive"]
    t.add_row("evasive", "swerves / full brakings / collisions",
              " / ".join(fmt(evasive[k], "{}") for k in ("swerves", "full_braking", "collisions"))
              if result["lane_changes_on"] else "off")
    for task in cfg.tasks:
        group = result[task.name]
        name = f"{task.name} ({cfg.source(task.name).value})"
        for h in task.headline:
            t.add_row(escape(name), escape(h.label), fmt(group.get(h.key), h.fmt))
            name = ""
        if task.outcome is not None and (events := group.get(task.outcome.key)):
            t.add_row(escape(name), escape(task.outcome.label), f"{sum(events)} of {len(events)}")
    timing = result["timing_ms"]
    t.add_row("timing", escape("render [ms/frame]"), fmt(timing["render"]))
    t.add_row("", escape("perception [ms/frame]"), fmt(timing["perception_total"]))
    return t
