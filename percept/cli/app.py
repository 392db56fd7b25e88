"""The percept command line (typer). Parses options, builds configs, calls the library, prints."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Optional

import typer
from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn
from rich.table import Table

app = typer.Typer(add_completion=False, no_args_is_help=True,
                  help="percept: a camera-only driving stack on highway-env, with a simulated stereo camera.")
console = Console()
err = Console(stderr=True)


def fail(message: str) -> None:
    err.print(f"[bold red]error:[/] {escape(message)}", highlight=False, soft_wrap=True)
    raise typer.Exit(2)


def progress_bar() -> Progress:
    return Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeRemainingColumn(),
                    console=err, transient=False)


def write_json(path: Optional[Path], data: dict) -> None:
    if path is None:
        return
    try:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        Path(path).write_text(json.dumps(data, indent=2))
    except OSError as e:
        fail(f"cannot write {path}: {e.strerror or e}")


@app.command()
def scenarios(json_path: Optional[Path] = typer.Option(None, "--json", help="Also write the list to this JSON file.")):
    """List the scenarios and the conditions any of them can run in."""
    from percept.sims import CONDITION_SUMMARY, SCENARIOS

    t = Table(title="scenarios")
    t.add_column("name")
    t.add_column("default duration [s]", justify="right")
    t.add_column("what happens")
    for s in SCENARIOS.values():
        t.add_row(s.name, f"{s.duration_s:.0f}", s.summary)
    console.print(t)
    c = Table(title="conditions (--condition, any scenario)")
    c.add_column("name")
    c.add_column("what changes")
    for k, v in CONDITION_SUMMARY.items():
        c.add_row(k.value, v)
    console.print(c)
    write_json(json_path, {"scenarios": {s.name: {"summary": s.summary, "duration_s": s.duration_s}
                                         for s in SCENARIOS.values()},
                           "conditions": {k.value: v for k, v in CONDITION_SUMMARY.items()}})


@app.command()
def render(
    scenario: str = typer.Option("highway", help="Scenario name (see `percept scenarios`)."),
    frames: int = typer.Option(..., help="Number of consecutive frames (15 per simulated second)."),
    out: Path = typer.Option(..., help="Output folder; created if missing."),
    seed: int = typer.Option(0, help="Random seed: the same seed renders byte-identical frames."),
    condition: str = typer.Option("clear", help="clear | night | rain | glare | noise | dropout."),
    scenery: bool = typer.Option(True, help="Roadside clutter (rails, poles, trees, buildings)."),
):
    """Render stereo PNGs, depth and ground truth of a scenario; the ego is driven by highway-env's IDM autopilot.

    Writes for frame i: DIR/{i:06d}_left.png, _right.png (absent when the frame was dropped), _depth.npy
    (float32 metres, inf for sky), _gt.json; plus DIR/camera.json and, with landmark signs, DIR/landmarks.json.
    """
    from percept.sims import SimWorld, WorldConfig
    from percept.sims.export import prepare_out_dir, render_run

    if frames < 1:
        fail(f"--frames must be at least 1, got {frames}")
    try:
        cfg = WorldConfig(scenario=scenario, seed=seed, condition=condition, autopilot=True, scenery=scenery)
        prepare_out_dir(out)
    except ValueError as e:
        fail(str(e))
    world = SimWorld(cfg)
    with progress_bar() as bar:
        task = bar.add_task(f"rendering {scenario}/{cfg.condition.value}/seed {seed}", total=frames)
        try:
            render_run(world, frames, out, progress=lambda: bar.advance(task))
        except (ValueError, OSError) as e:
            fail(str(e))
    console.print(f"wrote {frames} frames to {out}")


@app.command()
def drive(
    scenario: str = typer.Option("highway", help="Scenario name (see `percept scenarios`)."),
    seed: int = typer.Option(0, help="Random seed; the same seed and options give the same metrics."),
    condition: str = typer.Option("clear", help="clear | night | rain | glare | noise | dropout."),
    duration: Optional[float] = typer.Option(None, help="Simulated seconds (default: the scenario's own)."),
    lateral: str = typer.Option("privileged", help="Lateral slot: vision | privileged."),
    longitudinal: str = typer.Option("privileged", help="Longitudinal slot: vision | privileged."),
    pedestrians: str = typer.Option("privileged", help="Pedestrian slot: vision | privileged."),
    odometry: str = typer.Option("privileged", help="Odometry slot: vision | privileged."),
    record: Optional[Path] = typer.Option(None, help="Rerun recording path "
                                                     "(default runs/<scenario>-<condition>-<seed>.rrd)."),
    no_record: bool = typer.Option(False, "--no-record", help="Do not write a Rerun recording."),
    json_path: Optional[Path] = typer.Option(None, "--json", help="Write the run metrics to this JSON file."),
):
    """Drive a scenario in closed loop from the cameras, score it against ground truth and record it to Rerun."""
    from percept.drive import DriveConfig, run_drive
    from percept.review import RunRecorder
    from percept.sims import WorldConfig

    try:
        cfg = DriveConfig(WorldConfig(scenario=scenario, seed=seed, condition=condition), duration, lateral,
                          longitudinal, pedestrians, odometry)
    except ValueError as e:
        fail(str(e))
    rec_path = None if no_record else (record or Path("runs") / f"{scenario}-{cfg.world.condition.value}-{seed}.rrd")
    for p in (rec_path, json_path):
        if p is not None:
            try:
                Path(p).parent.mkdir(parents=True, exist_ok=True)
                probe = Path(p).with_name(Path(p).name + ".probe")
                probe.write_text("")
                probe.unlink()
            except OSError as e:
                fail(f"cannot write {p}: {e.strerror or e}")
    recorder_box = {}

    def make_recorder(world):
        lines = [s.left for s in world.road_geometry.strips] + [s.right for s in world.road_geometry.strips]
        recorder_box["r"] = RunRecorder(rec_path, world.cfg.rig, lines)
        return recorder_box["r"]

    with progress_bar() as bar:
        task = bar.add_task(f"driving {scenario}/{cfg.world.condition.value}/seed {seed}", total=None)
        try:
            # frames are rendered when a slot or the recording needs them
            result = run_drive(cfg, recorder_factory=make_recorder if rec_path else None,
                               progress=lambda i, n: bar.update(task, completed=i, total=n),
                               render=rec_path is not None or cfg.needs_cameras)
        finally:
            if "r" in recorder_box:
                recorder_box["r"].close()
    write_json(json_path, result)
    t = Table(title=f"{scenario} / {result['condition']} / seed {seed}: {result['frames']} frames, "
                    f"{result['duration_s']:.1f} s, realtime x{result['realtime_factor']:.2f}")
    t.add_column("metric")
    t.add_column("value", justify="right")
    lane, lon = result["lane"], result["longitudinal"]
    rows = [("collisions", result["collisions"]), ("pedestrian collisions", result["pedestrian_collisions"]),
            ("lane departures", result["lane_departures"]),
            ("centering RMS / max [m]", _pair(lane["centering_rms_m"], lane["centering_max_m"], "{:.3f}")),
            ("time gap mean / min [s]", _pair(lon["time_gap_mean_s"], lon["time_gap_min_s"])),
            ("pedestrian stops", str(result["pedestrians"]["stops"])),
            ("render [ms/frame]", _num(result["timing_ms"]["render"]))]
    if lane["offset_rmse_m"] is not None:
        rows += [("lane offset RMSE [m]", _num(lane["offset_rmse_m"], "{:.4f}")),
                 ("lane heading RMSE [rad]", _num(lane["heading_rmse_rad"], "{:.4f}")),
                 ("lane curvature RMSE [1/m]", _num(lane["curvature_rmse_1pm"], "{:.5f}")),
                 ("lanes [ms/frame]", _num(result["timing_ms"]["lanes"]))]
    for k, v in rows:
        t.add_row(escape(k), str(v))
    console.print(t)
    if rec_path:
        console.print(f"recording: {rec_path}  (open it with `percept view {rec_path}`)")


def _num(x, fmt: str = "{:.2f}") -> str:
    return "n/a" if x is None else fmt.format(x)


def _pair(a, b, fmt: str = "{:.2f}") -> str:
    return f"{_num(a, fmt)} / {_num(b, fmt)}"


@app.command()
def bench(
    json_path: Optional[Path] = typer.Option(None, "--json", help="Also write the figures to this JSON file."),
    frames: int = typer.Option(30, help="Timed calls per stage (median is reported)."),
):
    """Per-stage cost on one thread, against the named peers measured in the same run (ratio = ours / peer)."""
    from percept.drive.bench import bench_lanes, bench_render

    if frames < 1:
        fail(f"--frames must be at least 1, got {frames}")
    with progress_bar() as bar:
        task = bar.add_task("benchmarking", total=3 * (frames + 2))
        tick = lambda: bar.advance(task)  # noqa: E731
        results = [bench_render(frames, progress=tick), bench_lanes(frames, progress=tick)]
    t = Table(title="percept bench (one thread, median ms per call)")
    for col in ("stage", "ms", "target ms", "peer", "peer ms", "ratio"):
        t.add_column(col, justify="left" if col in ("stage", "peer") else "right")
    for r in results:
        t.add_row(r.stage, f"{r.ms:.2f}", _num(r.target_ms), r.peer or "-", _num(r.peer_ms), _num(r.ratio))
    console.print(t)
    write_json(json_path, {"stages": [r.to_dict() for r in results]})


def main() -> None:
    app()


# commands that live in their own modules register themselves on ``app``
from . import calibrate_cmd, eval_cmd, lanes_cmd, view_cmd  # noqa: E402

eval_cmd.register(app)
lanes_cmd.register(app)
calibrate_cmd.register(app)
view_cmd.register(app)
