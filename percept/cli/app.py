"""The percept command line (typer): the app, and every command registered from its own module."""

from __future__ import annotations

import typer

from . import options as opt
from . import (bench_cmd, calibrate_cmd, detect_cmd, drive_cmd, eval_cmd, lanes_cmd, odometry_cmd, render_cmd,
               scenarios_cmd, stereo_cmd, train_cmd, view_cmd)
from .common import Command, Group, console, err, fail, progress_bar, run_cli, write_json

app = typer.Typer(add_completion=False, no_args_is_help=True, cls=Group,
                  help="percept: a camera-only driving stack on highway-env, with a simulated stereo camera.")

app.command("scenarios", cls=Command)(scenarios_cmd.scenarios)
app.command("drive", cls=Command)(opt.with_task_options(drive_cmd.drive))
app.command("render", cls=Command)(render_cmd.render)
app.command("eval", cls=Command)(opt.with_task_options(eval_cmd.eval_))
app.command("bench", cls=Command)(bench_cmd.bench)
app.command("stereo", cls=Command)(stereo_cmd.stereo)
app.command("odometry", cls=Command)(odometry_cmd.odometry)
app.command("train-detector", cls=Command)(train_cmd.train_detector)
lanes_cmd.register(app)
detect_cmd.register(app)
calibrate_cmd.register(app)
view_cmd.register(app)

__all__ = ["app", "console", "err", "fail", "main", "progress_bar", "write_json"]


def main() -> None:
    """The console script: library chatter off, Ctrl-C -> one line saying what was kept, exit code 130."""
    run_cli(app)
