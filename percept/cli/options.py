"""Options shared by several commands, defined once (typer ``Annotated`` aliases; choices are Enums, so --help
lists them)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Optional

import typer

from percept.sensors.records import Source


MAX_SEED = 2**31 - 1
_SLOT = "{task} slot: vision (its perception module) or privileged (ground truth, the baseline)."

Scenario = Annotated[str, typer.Option("--scenario", help="Scenario name (see `percept scenarios`).")]
Seed = Annotated[int, typer.Option("--seed", help="Random seed (0 to 2^31-1); the same seed and options give the "
                                                  "same metrics.")]
Condition = Annotated[str, typer.Option("--condition", help="clear | night | rain | glare | noise | dropout.")]
Duration = Annotated[Optional[float], typer.Option("--duration", help="Simulated seconds (default: the "
                                                                      "scenario's own).")]
Lateral = Annotated[Source, typer.Option("--lateral", help=_SLOT.format(task="Lateral (lanes, steering)"))]
Longitudinal = Annotated[Source, typer.Option("--longitudinal", help=_SLOT.format(
    task="Longitudinal (lead range, following, braking)"))]
Pedestrians = Annotated[Source, typer.Option("--pedestrians", help=_SLOT.format(task="Pedestrian"))]
Odometry = Annotated[Source, typer.Option("--odometry", help=_SLOT.format(task="Odometry"))]
JsonOut = Annotated[Optional[Path], typer.Option("--json", help="Also write the results to this JSON file.",
                                                 dir_okay=False)]


def check_number(flag: str, value, lo: float | None = None, hi: float | None = None):
    """The one place a number from the command line is checked by its meaning: finite and within [lo, hi]; a
    one-line error (exit 2) naming the option otherwise. Returns the value; None passes (option not given)."""
    from .common import fail

    if value is None:
        return None
    if not math.isfinite(value) or (lo is not None and value < lo) or (hi is not None and value > hi):
        span = (f"between {lo:g} and {hi:g}" if lo is not None and hi is not None
                else f"at least {lo:g}" if lo is not None else f"at most {hi:g}")
        fail(f"{flag} must be a finite number {span}, got {value}")
    return value


def slot_sources(lateral: Source, longitudinal: Source, pedestrians: Source, odometry: Source) -> dict:
    """The slot options as the ``sources`` of a DriveConfig."""
    return {"lateral": lateral, "longitudinal": longitudinal, "pedestrians": pedestrians, "odometry": odometry}
