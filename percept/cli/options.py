"""Options shared by several commands, defined once (typer ``Annotated`` aliases; choices are Enums, so --help
lists them)."""

from __future__ import annotations

import functools
import inspect
import math
from pathlib import Path
from typing import Annotated, Callable, Optional

import typer

from percept.drive.limits import MAX_DURATION_S, MAX_SEED
from percept.sensors.records import Source


_SLOT = ("The {task} slot, {help}: vision (its perception module; the default) or privileged (ground truth, the "
         "baseline; --privileged sets every slot).")

Scenario = Annotated[str, typer.Option("--scenario", help="Scenario name (see `percept scenarios`).")]
Seed = Annotated[int, typer.Option("--seed", help="Random seed (0 to 2^31-1); the same seed and options give the "
                                                  "same metrics.")]
Condition = Annotated[str, typer.Option("--condition", help="Weather or camera condition: clear | night | rain | "
                                                            "glare | noise | dropout (see `percept scenarios`).")]
Duration = Annotated[Optional[float], typer.Option("--duration", help=f"Simulated seconds, at most "
                                                   f"{MAX_DURATION_S:g} (default: the scenario's own).")]
Detector = Annotated[str, typer.Option("--detector", help="People model of the vision pedestrian slot: sim "
                                       "(trained on rendered people), inria (OpenCV's) or a model file.")]
Rear = Annotated[Optional[bool], typer.Option("--rear/--no-rear", help="The rear stereo rig, looking back from the rear "
                                              "bumper, on or off (default: on where the scenario's traffic changes "
                                              "lanes).", show_default=False)]
LaneChanges = Annotated[str, typer.Option("--lane-changes", help="on: the car changes lanes when MOBIL on what it "
                                          "sees favours it and it is safe, and swerves into a free lane when braking "
                                          "alone falls short (never without the rear rig); off: it keeps its lane.")]


def lane_changes_on(value: str) -> bool:
    """--lane-changes as a bool; a one-line exit 2 on anything but on or off."""
    if value not in ("on", "off"):
        from .common import fail

        fail(f"--lane-changes must be on or off, got '{value}'")
    return value == "on"


JsonOut = Annotated[Optional[Path], typer.Option("--json", help="Also write the results to this JSON file.",
                                                 dir_okay=False)]


def flag(*names: str, help: str):
    """An on/off option (``Annotated[bool, flag("--force", help=...)]``): --help shows it without a value type,
    where typer would print ``<bool>`` as if it took one."""
    return typer.Option(*names, help=help, metavar="")


Privileged = Annotated[bool, flag("--privileged", help="Every slot on ground truth: the baselines the vision modules "
                                                       "are measured against (a slot's own option still wins).")]


def check_number(flag: str, value, lo: float | None = None, hi: float | None = None):
    """The one place a number from the command line is checked by its meaning: finite and within [lo, hi]; a
    one-line error (exit 2) naming the option otherwise. Returns the value; None passes (option not given)."""
    from .common import fail

    if value is None:
        return None
    if not math.isfinite(value) or (lo is not None and value < lo) or (hi is not None and value > hi):
        span = (f"between {_bound(lo)} and {_bound(hi)}" if lo is not None and hi is not None
                else f"at least {_bound(lo)}" if lo is not None else f"at most {_bound(hi)}")
        fail(f"{flag} must be a finite number {span}, got {value}")
    return value


def _bound(x: float) -> str:
    """A limit as written in a message: whole numbers in full (2147483647, not 2.14748e+09), others short."""
    return str(int(x)) if float(x).is_integer() and abs(x) < 1e16 else f"{x:g}"


def with_task_options(command: Callable) -> Callable:
    """``command`` with one ``--NAME vision|privileged`` option per task of the slot table in place of its
    ``sources`` parameter, which receives them as a dict (task name -> Source, or None where not given): the CLI
    offers whatever tasks the table holds."""
    from percept.drive.tasks import TASKS

    sig = inspect.signature(command, eval_str=True)
    task_params = [inspect.Parameter(t.name, inspect.Parameter.KEYWORD_ONLY, default=None,
                                     annotation=Annotated[Optional[Source], typer.Option(
                                         f"--{t.name}", help=_SLOT.format(task=t.name, help=t.help))])
                   for t in TASKS]
    params = []
    for p in sig.parameters.values():
        params += task_params if p.name == "sources" else [p.replace(kind=inspect.Parameter.KEYWORD_ONLY)]

    @functools.wraps(command)
    def run(**kwargs):
        return command(sources={t.name: kwargs.pop(t.name) for t in TASKS}, **kwargs)

    run.__signature__ = sig.replace(parameters=params)
    run.__annotations__ = {p.name: p.annotation for p in params}
    del run.__wrapped__  # typer reads the signature above, not the wrapped one's
    return run


def slot_sources(given: dict, privileged: bool = False) -> dict:
    """The task options (task name -> Source or None) as the ``sources`` of a DriveConfig: a slot not given is on
    vision, or on ground truth with ``--privileged``."""
    default = Source.PRIVILEGED if privileged else Source.VISION
    return {task: default if src is None else src for task, src in given.items()}
