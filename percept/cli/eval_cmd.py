"""`percept eval`: the closed loop over scenarios x conditions x seeds, locally or on a Ray cluster."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, List, Optional

import typer
from rich import box
from rich.markup import escape
from rich.table import Table

from percept.sensors.records import Source

from . import options as opt
from .common import check_outputs, console, fail, fmt, progress_bar, write_json


def eval_(
    scenario: Annotated[List[str], typer.Option("--scenario", help="Scenario name; repeat for several, or 'all'.")],
    out: Annotated[Path, typer.Option("--out", file_okay=False, help="Output folder: runs/<scenario>-<condition>-"
                                      "<seed>.json and summary.json. Runs already there are reused (resume).")],
    seeds: Annotated[str, typer.Option("--seeds", help="Seeds: A-B (inclusive), N, or A,B,C.")] = "0-4",
    condition: Annotated[List[str], typer.Option("--condition", help="Condition; repeat for several.")] = ["clear"],
    workers: Annotated[int, typer.Option("--workers", help="Parallel runs on this machine (local engine), 1 to "
                                                           "256.")] = 1,
    engine: Annotated[str, typer.Option("--engine", help="local | ray.")] = "local",
    address: Annotated[Optional[str], typer.Option("--address", help="Ray cluster address (default: start a "
                                                                     "local Ray).")] = None,
    duration: opt.Duration = None,
    lateral: opt.Lateral = Source.PRIVILEGED,
    longitudinal: opt.Longitudinal = Source.PRIVILEGED,
    pedestrians: opt.Pedestrians = Source.PRIVILEGED,
    odometry: opt.Odometry = Source.PRIVILEGED,
    json_path: opt.JsonOut = None,
):
    """Drive every (scenario, condition, seed) and summarise the metrics per scenario and condition.

    Each finished run is written at once, so an interrupted batch keeps its runs and the same command
    resumes it; a run that fails is listed with its error and the others go on.
    """
    from percept.drive import TASKS
    from percept.drive.batch import Engine, EvalPlan, evaluate, parse_seeds
    from percept.sims import SCENARIOS

    opt.check_number("--workers", workers, 1, 256)
    names = list(SCENARIOS) if "all" in scenario else scenario
    try:
        eng = Engine(engine)
    except ValueError:
        fail(f"--engine must be local or ray, got '{engine}'")
    try:
        plan = EvalPlan(tuple(dict.fromkeys(names)), tuple(dict.fromkeys(condition)), tuple(parse_seeds(seeds)),
                        opt.slot_sources(lateral, longitudinal, pedestrians, odometry), duration)
    except ValueError as e:
        fail(str(e))
    check_outputs([out / "summary.json", json_path])
    with progress_bar() as bar:
        task = bar.add_task(f"eval {len(plan.jobs)} runs", total=len(plan.jobs))
        try:
            summary = evaluate(plan, out, workers, eng, address, progress=lambda r: bar.advance(task))
        except RuntimeError as e:
            fail(str(e))
    console.print(summary_table(summary, TASKS))
    console.print(f"all metrics per scenario and condition (mean / max / min): {out / 'summary.json'}")
    for g in summary["groups"]:
        for f in g["failed"]:
            console.print(f"[red]failed[/] {escape(g['scenario'])}/{g['condition']}/seed {f['seed']}: "
                          f"{escape(f['error'])}")
    write_json(json_path, summary)


def summary_table(summary: dict, tasks) -> Table:
    """Per scenario and condition: runs, summed safety counts, and each task's headline metrics (mean over seeds)
    for the metrics some run has."""
    cols = [(t, h) for t in tasks for h in t.headline
            if any((g[t.group].get(h.key) or None) is not None for g in summary["groups"])]
    t = Table(title=f"{sum(len(g['seeds']) for g in summary['groups'])} runs; slots: "
                    + ", ".join(f"{k} {v}" for k, v in summary["slots"].items()),
              box=box.SIMPLE_HEAD, pad_edge=False, collapse_padding=True, caption="means over seeds")
    for col in ("scenario", "cond", "runs", "coll", "ped", "dep"):
        t.add_column(col, justify="left" if col in ("scenario", "cond") else "right", no_wrap=True)
    for _, h in cols:
        t.add_column(escape(h.label), justify="right")
    for g in summary["groups"]:
        cells = [fmt((g[task.group].get(h.key) or {}).get("mean"), h.fmt.replace("{}", "{:.1f}"))
                 for task, h in cols]
        t.add_row(g["scenario"], g["condition"], str(len(g["seeds"])), fmt(g["collisions"], "{}"),
                  fmt(g["pedestrian_collisions"], "{}"), fmt(g["lane_departures"], "{}"), *cells)
    return t
