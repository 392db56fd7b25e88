"""`percept drive`: one closed-loop run, scored against ground truth and recorded to Rerun."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Optional

import typer
from rich.markup import escape
from rich.table import Table

from percept.sensors.records import Source

from . import options as opt
from .common import check_outputs, console, fail, fmt, progress_bar, write_json


def drive(
    scenario: opt.Scenario = "highway",
    seed: opt.Seed = 0,
    condition: opt.Condition = "clear",
    duration: opt.Duration = None,
    lateral: opt.Lateral = Source.PRIVILEGED,
    longitudinal: opt.Longitudinal = Source.PRIVILEGED,
    pedestrians: opt.Pedestrians = Source.PRIVILEGED,
    odometry: opt.Odometry = Source.PRIVILEGED,
    record: Annotated[Optional[Path], typer.Option(
        "--record", dir_okay=False, help="Rerun recording path (default runs/<scenario>-<condition>-<seed>.rrd).")] = None,
    no_record: Annotated[bool, typer.Option("--no-record", help="Do not write a Rerun recording.")] = False,
    json_path: opt.JsonOut = None,
):
    """Drive a scenario in closed loop from the cameras, score it against ground truth and record it to Rerun."""
    from percept.drive import DriveConfig, run_drive
    from percept.sims import WorldConfig

    opt.check_number("--seed", seed, 0, opt.MAX_SEED)
    try:
        cfg = DriveConfig(WorldConfig(scenario=scenario, seed=seed, condition=condition), duration,
                          opt.slot_sources(lateral, longitudinal, pedestrians, odometry))
    except ValueError as e:
        fail(str(e))
    rec_path = None if no_record else (record or Path("runs") / f"{scenario}-{cfg.world.condition.value}-{seed}.rrd")
    check_outputs([rec_path, json_path])
    holder = {}

    def make_recorder(world):
        from percept.review import RunRecorder

        lines = [s.left for s in world.road_geometry.strips] + [s.right for s in world.road_geometry.strips]
        holder["r"] = RunRecorder(rec_path, world.cfg.rig, lines, cfg.tasks)
        return holder["r"]

    with progress_bar() as bar:
        task = bar.add_task(f"driving {scenario}/{cfg.world.condition.value}/seed {seed}", total=None)
        try:
            # frames are rendered when a slot or the recording needs them
            result = run_drive(cfg, recorder_factory=make_recorder if rec_path else None,
                               progress=lambda i, n: bar.update(task, completed=i, total=n),
                               render=rec_path is not None or cfg.needs_cameras)
        except BaseException:
            if "r" in holder:
                holder["r"].close(complete=False)
            raise
    if "r" in holder:
        holder["r"].close()
    write_json(json_path, result)
    console.print(summary_table(cfg, result))
    if rec_path:
        console.print(f"recording: {rec_path}  (open it with `percept view {rec_path}`)")


def summary_table(cfg, result: dict) -> Table:
    """The run's safety counts and every task's headline metrics (n/a where one does not apply)."""
    t = Table(title=f"{result['scenario']} / {result['condition']} / seed {result['seed']}: {result['frames']} "
                    f"frames, {result['duration_s']:.1f} s, realtime x{result['realtime_factor']:.2f}")
    for col, just in (("task", "left"), ("metric", "left"), ("value", "right")):
        t.add_column(col, justify=just)
    for k in ("collisions", "pedestrian_collisions", "lane_departures"):
        t.add_row("run", k.replace("_", " "), fmt(result[k], "{}"))
    for task in cfg.tasks:
        group = result[task.group]
        name = f"{task.name} ({cfg.source(task.name).value})"
        for h in task.headline:
            t.add_row(escape(name), escape(h.label), fmt(group.get(h.key), h.fmt))
            name = ""
    if task_stops := result.get("pedestrians", {}).get("stops"):
        t.add_row("pedestrians", "stopped for crossings", f"{sum(task_stops)} of {len(task_stops)}")
    timing = result["timing_ms"]
    t.add_row("timing", "render [ms/frame]", fmt(timing["render"]))
    t.add_row("", "perception [ms/frame]", fmt(timing["perception_total"]))
    return t
