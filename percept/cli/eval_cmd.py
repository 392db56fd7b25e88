"""`percept eval`: the closed loop over scenarios x conditions x seeds, locally or on a Ray cluster."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, List, Optional

import typer
from rich import box
from rich.console import Group
from rich.markup import escape
from rich.table import Table

from . import options as opt
from .common import check_outputs, console, err, fail, fmt, on_interrupt, only_writer, progress_bar, write_json


def eval_(
    scenario: Annotated[List[str], typer.Option("--scenario", help="Scenario name; repeat for several, or 'all'.")],
    out: Annotated[Path, typer.Option("--out", file_okay=False, help="Output folder: runs/<scenario>-<condition>-"
                                      "<seed>.json and summary.json. Runs already there with the same settings are "
                                      "reused (resume); runs made with other settings stop the batch (see --redo).")],
    seeds: Annotated[str, typer.Option("--seeds", help="Seeds: A-B (inclusive), N, or A,B,C; each 0 to 2^31-1, at "
                                                       "most 10,000 of them.")] = "0-4",
    condition: Annotated[List[str], typer.Option("--condition", help="Condition (see `percept scenarios`); repeat "
                                                                     "for several.")] = ["clear"],
    workers: Annotated[int, typer.Option("--workers", help="Parallel runs on this machine (local engine), 1 to "
                                                           "256.")] = 1,
    engine: Annotated[str, typer.Option("--engine", help="Where the runs go: local (worker processes on this "
                                                         "machine) or ray (a Ray cluster, see --address).")] = "local",
    address: Annotated[Optional[str], typer.Option("--address", help="Ray cluster address (default: start a "
                                                                     "local Ray).")] = None,
    duration: opt.Duration = None,
    sources: dict = None,
    detector: opt.Detector = "sim",
    privileged: opt.Privileged = False,
    rear: opt.Rear = None,
    lane_changes: opt.LaneChanges = "on",
    ego: Annotated[str, typer.Option("--ego", help="Who drives: percept (its agent on its slots) or mobil "
                                                   "(highway-env's IDM car changing lanes by MOBIL in the ego's place, "
                                                   "on truth: the anchor for progress).")] = "percept",
    json_path: opt.JsonOut = None,
    redo: Annotated[bool, opt.flag("--redo", help="Drive again the runs in --out that were made with other "
                                                      "settings (other slots, duration or percept version).")] = False,
    strict: Annotated[bool, opt.flag("--strict", help="Exit 1 when any run has a collision, a pedestrian "
                                                          "collision, a lane departure or an unsafe lane change "
                                                          "(listed, each with the command that reproduces "
                                                          "it).")] = False,
):
    """Drive every (scenario, condition, seed) and summarise the metrics per scenario and condition.

    Besides the runs and summary.json, --out gets summary.csv (every metric per scenario and condition: runs,
    mean, p95, worst), summary.md (safety counts, headline metrics, runs to look at with the command that
    reproduces each) and plots/*.png.

    Each finished run is written at once (complete or absent), so an interrupted batch keeps its runs and the
    same command resumes it. A run is reused only if it was made with the same settings (slots, duration, percept
    version); a damaged run file is listed and driven again. A run that fails is listed with its error, the others
    go on, and the exit code is 1. While it runs, --out holds .percept-lock (its pid, host and command line): a
    second command writing there is refused at once, and a lock left by a process that no longer runs is taken over.
    """
    plan, eng = _plan(scenario, condition, seeds, workers, engine, duration, detector,
                      opt.slot_sources(sources, privileged), rear, opt.lane_changes_on(lane_changes), ego)
    _refuse_unused(ego, sources, detector, address, eng)
    with only_writer(out, "percept eval"):
        files = _scan(plan, out, redo)
        _check_outputs(plan, out, json_path)
        for path, why in files.damaged:
            err.print(f"[yellow]redoing[/] {escape(str(path))}: {why}", highlight=False, soft_wrap=True)
        summary = _run(plan, out, workers, eng, address, redo, files)
        console.print(summary_tables(summary, plan.tasks))
        console.print(f"every metric per scenario and condition: {out / 'summary.csv'}; the report: "
                      f"{out / 'summary.md'}; plots in {out / 'plots'}")
        write_json(json_path, summary)
        _report_failures(summary, len(plan.jobs), out)
        if strict:
            _strict(summary)


def _check_outputs(plan, out: Path, json_path: Path | None) -> None:
    """``check_outputs`` of the batch's files, with the people model as an input; a one-line exit 2 for a --json
    that is one of the files eval writes in ``out`` (its summaries, its lock, anything in runs/ or plots/), or for a
    summary file there that eval did not write."""
    from percept.detection import LinearModel
    from percept.evaluate import SUMMARY_STARTS, written_by_eval
    from percept.folder_lock import LOCK_NAME

    if json_path is not None and out.resolve() in json_path.resolve().parents:
        top = json_path.resolve().relative_to(out.resolve()).parts[0]
        if top in ("runs", "plots", *SUMMARY_STARTS, LOCK_NAME):
            fail(f"--json {json_path} is where eval writes its own results in --out {out}; give another path")
    if (out / "plots").exists() and not (out / "plots").is_dir():
        fail(f"{out / 'plots'} is a file, where eval writes its plots; move it or choose another --out")
    for path in (out / name for name in SUMMARY_STARTS):
        if path.is_file() and not written_by_eval(path):
            fail(f"{path} was not written by percept eval and would be replaced; move it or choose another --out")
    check_outputs([out / "summary.json", out / "runs" / f"{plan.jobs[0].name}.json", json_path],
                  [LinearModel.file_of(plan.detector)])


def _refuse_unused(ego: str, given: dict, detector: str, address: str | None, eng) -> None:
    """A one-line exit 2 for options that would be ignored: slot options (``given``: task -> Source or None) or a
    people model with highway-env's MOBIL car as the ego, an --address the engine does not use; or for a Ray cluster
    that does not answer at --address (Ray itself would retry for minutes)."""
    import socket

    from percept.evaluate.plan import Engine

    if ego == "mobil" and (any(src is not None for src in given.values()) or detector != "sim"):
        fail("--ego mobil puts highway-env's own car in the ego's place, on ground truth: no slot runs, so leave out "
             "the slot options and --detector")
    if address is None or address == "auto":
        return
    if eng is not Engine.RAY:
        fail("--address names a Ray cluster; give it with --engine ray")
    host, _, port = address.removeprefix("ray://").rpartition(":")
    if not host or not port.isdigit():
        fail(f"--address must be HOST:PORT (or ray://HOST:PORT, or auto), got '{address}'")
    try:
        socket.create_connection((host, int(port)), timeout=5).close()
    except OSError as e:
        fail(f"no Ray cluster answers at {address} ({e.strerror or e}); start one (`ray start --head`) or leave "
             f"out --address for a local Ray")


def _plan(scenario, condition, seeds, workers, engine, duration, detector, sources, rear=None, lane_changes=True,
          ego="percept"):
    """The checked options as (EvalPlan, Engine), the model file included; one-line exit 2 otherwise."""
    from percept.evaluate.plan import Engine, EvalPlan, parse_seeds
    from percept.sims import SCENARIOS

    opt.check_number("--workers", workers, 1, 256)
    opt.check_number("--duration", duration, 1e-3, opt.MAX_DURATION_S)
    if "all" in scenario and len(set(scenario)) > 1:
        fail("--scenario all already means every scenario; give either all or scenario names, not both")
    names = list(SCENARIOS) if "all" in scenario else scenario
    try:
        eng = Engine(engine)
    except ValueError:
        fail(f"--engine must be local or ray, got '{engine}'")
    try:
        plan = EvalPlan(tuple(dict.fromkeys(names)), tuple(dict.fromkeys(condition)), tuple(parse_seeds(seeds)),
                        sources, duration, detector, rear=rear, lane_changes=lane_changes, ego=ego)
    except ValueError as e:
        fail(str(e))
    return plan, eng


def _scan(plan, out: Path, redo: bool):
    """The run files of ``plan`` already in ``out``, read once the folder is this command's; one-line exit 2 when
    some were made with other settings (and not ``redo``) or a folder is in the way."""
    from percept.evaluate.resume import refuse_other_settings, scan_runs

    try:
        files = scan_runs(plan, out)
        if not redo:
            refuse_other_settings(files, out)
    except ValueError as e:
        fail(str(e))
    return files


def _strict(summary: dict) -> None:
    """--strict: list every run with a collision, a pedestrian collision, a lane departure or an unsafe lane change
    and exit 1."""
    for u in summary["unsafe"]:
        console.print(f"[red]unsafe[/] {escape(u['scenario'])}/{u['condition']}/seed {u['seed']}: {u['what']}; "
                      f"reproduce: {escape(u['reproduce'])}", soft_wrap=True)
    if summary["unsafe"]:
        err.print(f"[bold red]error:[/] --strict: {len(summary['unsafe'])} run(s) had a collision, a pedestrian "
                  "collision, a lane departure or an unsafe lane change (listed above)", highlight=False,
                  soft_wrap=True)
        raise typer.Exit(1)


def _report_failures(summary: dict, total: int, out: Path) -> None:
    """List the failed runs, then exit with code 1 saying how many failed (nothing when none did)."""
    failed = [(g, f) for g in summary["groups"] for f in g["failed"]]
    for g, f in failed:
        console.print(f"[red]failed[/] {escape(g['scenario'])}/{g['condition']}/seed {f['seed']}: "
                      f"{escape(f['error'])}", soft_wrap=True)
    if failed:
        err.print(f"[bold red]error:[/] {len(failed)} of {total} runs failed (listed above); the others are kept in "
                  f"{escape(str(out / 'runs'))} and the same command drives the failed ones again",
                  highlight=False, soft_wrap=True)
        raise typer.Exit(1)


def _run(plan, out: Path, workers: int, eng, address, redo: bool, files) -> dict:
    """The batch under a progress bar; Ctrl-C says how many finished runs are kept."""
    from percept.evaluate.batch import evaluate
    from percept.evaluate.resume import run_path

    failed = [0]

    def advance(r: dict) -> None:
        failed[0] += "error" in r
        bar.update(task, advance=1, description=f"eval {len(plan.jobs)} runs, {failed[0]} failed")

    def kept() -> str:
        # counted on disk: a run is kept once its file is there, whether or not the bar has caught up with it
        n = sum(run_path(out, job).is_file() for job in plan.jobs)
        return f"{n} finished run{'' if n == 1 else 's'} kept in {out / 'runs'}; run the same command to resume"

    on_interrupt(kept)
    reused = len(files.done)  # finished runs of the same settings, reused whatever --redo says
    with progress_bar(long_steps=True) as bar:
        task = bar.add_task(f"eval {len(plan.jobs)} runs, 0 failed", total=len(plan.jobs), completed=reused,
                            start_completed=reused)
        try:
            return evaluate(plan, out, workers, eng, address, progress=advance, redo=redo, files=files)
        except (RuntimeError, ValueError) as e:
            fail(str(e))
        except OSError as e:
            fail(f"cannot write into {out}: {e.strerror or e}; the finished runs are kept, the same command resumes")


def summary_tables(summary: dict, tasks) -> Group:
    """Per scenario and condition, in tables that each fit 80 columns: the runs and their summed safety counts;
    then, per task, its headline metrics (mean over seeds) that some run has."""
    groups = summary["groups"]
    title = (f"{sum(len(g['seeds']) for g in groups)} runs; slots: "
             + ", ".join(f"{k} {v}" for k, v in summary["settings"]["slots"].items()))
    safety = _cells_table(title, ("runs", "collisions", "pedestrian collisions", "lane departures",
                                  "unsafe lane changes"))
    for g in groups:
        safety.add_row(g["scenario"], g["condition"], str(len(g["seeds"])),
                       *(fmt(g.get(k), "{}") for k in ("collisions", "pedestrian_collisions", "lane_departures",
                                                       "unsafe_lane_changes")))
    tables = [safety] + ([_run_table(groups)] if any(g.get("progress") for g in groups) else [])
    for task in tasks:
        heads = [h for h in task.headline if any((g[task.name].get(h.key) or None) is not None for g in groups)]
        if not heads:
            continue
        t = _cells_table(f"{task.name} (means over seeds)", [h.label for h in heads])
        for g in groups:
            t.add_row(g["scenario"], g["condition"], *(fmt((g[task.name].get(h.key) or {}).get("mean"),
                                                           h.fmt.replace("{}", "{:.1f}")) for h in heads))
        tables.append(t)
    return Group(*tables)


def _run_table(groups: list[dict]) -> Table:
    """Progress and lane changes per scenario and condition (means over seeds)."""
    from percept.evaluate.metrics import RUN_HEADLINES

    t = _cells_table("progress and lane changes (means over seeds)", [label for _, label, _ in RUN_HEADLINES])
    for g in groups:
        cells = []
        for key, _, spec in RUN_HEADLINES:
            grp, name = key.split(".")
            cells.append(fmt(((g.get(grp) or {}).get(name) or {}).get("mean"), spec))
        t.add_row(g["scenario"], g["condition"], *cells)
    return t


def _cells_table(title: str, columns) -> Table:
    """A table of one row per scenario and condition with these value columns (headers wrap, values do not)."""
    t = Table(title=escape(title), box=box.SIMPLE_HEAD, pad_edge=False, collapse_padding=True, title_justify="left")
    t.add_column("scenario", no_wrap=True)
    t.add_column("condition", no_wrap=True)
    for col in columns:
        t.add_column(escape(col), justify="right", min_width=8)
    return t
