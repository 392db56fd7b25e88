"""Batch evaluation: the closed loop over scenarios x conditions x seeds, one run JSON each, and a summary
(``summary.json``; ``summary.csv``, ``summary.md`` and ``plots/`` from ``percept.evaluate.report``).

Runs go to worker processes (``workers``, one OpenCV thread each) or to a Ray cluster. Each finished run is
written at once (atomically) to ``OUT/runs/<scenario>-<condition>-<seed>.json``, so an interrupted batch keeps
what it finished and the same batch again reuses it. A failed run is reported in the summary (not written: the
next batch drives it again); the others go on. Resume never mixes settings (``percept.evaluate.resume``): each run
file and the summary carry ``settings``; damaged run files are redone, runs made with other settings refused
before any work unless ``redo``.
"""

from __future__ import annotations

import contextlib
import signal
import traceback
from concurrent.futures import ProcessPoolExecutor, as_completed
from multiprocessing import get_context
from pathlib import Path
from typing import Callable, Iterator

import cv2
import numpy as np
from threadpoolctl import threadpool_limits

from percept.drive.limits import MAX_SEED
from percept.drive.loop import run_drive
from percept.outputs import write_json_atomic

from .environment import environments, numeric_environment
from .plan import MAX_SEEDS, Engine, EvalPlan, Job, parse_seeds
from .resume import (COUNTS, RunFiles, groups, differences, refuse_other_settings, run_path, run_settings,
                     scan_runs)

__all__ = ["MAX_SEED", "MAX_SEEDS", "Engine", "EvalPlan", "Job", "RunFiles", "differences", "evaluate",
           "parse_seeds", "refuse_other_settings", "run_job", "run_settings", "scan_runs", "summarize"]


def _worker_init() -> None:
    """A worker process: Ctrl-C is the parent's to handle (it terminates the workers)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def run_job(plan: EvalPlan, job: Job) -> dict:
    """Run one job (in a worker, on one thread: OpenCV's and numpy's BLAS, so that workers do not contend for the
    cores); the run JSON with the worker's ``environment`` (``numeric_environment``: what its numbers depend on besides
    the code), or {"scenario", "condition", "seed", "error", "traceback"}."""
    cv2.setNumThreads(1)
    try:
        cfg = plan.config(job)
        with threadpool_limits(1):
            return {**run_drive(cfg, render=cfg.needs_cameras), "environment": numeric_environment()}
    except Exception as e:  # noqa: BLE001 - one failed run must not take the batch down; it is reported
        return {"scenario": job.scenario, "condition": job.condition, "seed": job.seed,
                "error": f"{type(e).__name__}: {e}", "traceback": traceback.format_exc()}


def _local(plan: EvalPlan, jobs: list[Job], workers: int) -> Iterator[tuple[Job, dict]]:
    """Each job's (job, run JSON) as it finishes, in this process (one worker) or in ``workers`` processes."""
    if workers == 1:
        for job in jobs:
            yield job, run_job(plan, job)
        return
    # spawned workers: no state (OpenCV threads, pygame) copied from this process
    pool = ProcessPoolExecutor(max_workers=workers, mp_context=get_context("spawn"), initializer=_worker_init)
    finished = False
    try:
        futures = {pool.submit(run_job, plan, job): job for job in jobs}
        for f in as_completed(futures):
            yield futures[f], f.result()
        finished = True
    finally:
        if finished:
            pool.shutdown()
        else:
            _stop_pool(pool)


def _stop_pool(pool: ProcessPoolExecutor) -> None:
    """Ctrl-C or an error: drop the queued runs and end the running ones now (a run takes seconds to finish)."""
    processes = list((getattr(pool, "_processes", None) or {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for p in processes:
        p.terminate()
    for p in processes:
        p.join(timeout=1.0)


def _ray(plan: EvalPlan, jobs: list[Job], address: str | None) -> Iterator[tuple[Job, dict]]:
    """Each job's (job, run JSON) as it finishes on the Ray cluster at ``address`` (None: a local Ray)."""
    try:
        import ray
    except ImportError:
        raise RuntimeError("the ray engine needs Ray: pip install 'percept[ray]' (or use --engine local)") from None
    if not ray.is_initialized():
        ray.init(address=address, logging_level="ERROR", log_to_driver=False)
    # results travel back to this process, which writes them (cluster nodes need not share its disk)
    remote = ray.remote(num_cpus=1)(run_job)
    pending = {remote.remote(plan, job): job for job in jobs}
    try:
        while pending:
            done, _ = ray.wait(list(pending), num_returns=1)
            job = pending.pop(done[0])
            yield job, ray.get(done[0])
    finally:
        for ref in pending:  # Ctrl-C or an error: cancel what has not finished
            with contextlib.suppress(Exception):
                ray.cancel(ref, force=True)


def evaluate(plan: EvalPlan, out_dir: Path, workers: int = 1, engine: Engine = Engine.LOCAL,
             address: str | None = None, progress: Callable[[dict], None] | None = None,
             redo: bool = False, files: RunFiles | None = None) -> dict:
    """Run every job of ``plan`` without a finished run of the same settings in ``out_dir/runs``; write and return
    the summary. Damaged run files are redone; runs made under other settings raise ValueError before any work,
    or are redone with ``redo``. ``files``: a ``scan_runs`` already made (the CLI reports it first).
    ``progress(run)`` is called after each run this call drives (not for the finished runs it reuses)."""
    out_dir = Path(out_dir)
    files = files if files is not None else scan_runs(plan, out_dir)
    if not redo:
        refuse_other_settings(files, out_dir)
    (out_dir / "runs").mkdir(parents=True, exist_ok=True)
    settings = run_settings(plan)
    results = list(files.done.values())
    todo = [job for job in plan.jobs if job not in files.done]
    stream = _local(plan, todo, workers) if Engine(engine) is Engine.LOCAL else _ray(plan, todo, address)
    with contextlib.closing(stream):
        for job, r in stream:
            if "error" not in r:
                r = {**r, "settings": settings}
                write_json_atomic(run_path(out_dir, job), r)
            results.append(r)
            if progress:
                progress(r)
    from .report import reproduce_command, unsafe_runs, write_reports

    summary = {"settings": settings, **summarize(plan, results),
               "unsafe": [{"scenario": r["scenario"], "condition": r["condition"], "seed": r["seed"], "what": what,
                           "reproduce": reproduce_command(r, settings)} for r, what in unsafe_runs(results)]}
    write_json_atomic(out_dir / "summary.json", summary)
    write_reports(plan, results, settings, out_dir, plan.tasks)
    return summary


def _stats(values: list) -> dict | None:
    """Mean, max and min of the numbers among ``values`` (None where there are none)."""
    v = [x for x in values if x is not None and not isinstance(x, (list, dict, bool, str))]
    if not v:
        return None
    a = np.asarray(v, dtype=float)
    return {"mean": float(a.mean()), "max": float(a.max()), "min": float(a.min())}


def summarize(plan: EvalPlan, results: list[dict]) -> dict:
    """Per (scenario, condition): runs, failures, summed counts, and mean / max / min of every numeric metric
    (null where no run has it)."""
    cells = []
    for sc in plan.scenarios:
        for c in plan.conditions:
            rs = [r for r in results if r.get("scenario") == sc and r.get("condition") == c]
            ok = sorted((r for r in rs if "error" not in r), key=lambda r: r["seed"])
            g = {"scenario": sc, "condition": c, "seeds": [r["seed"] for r in ok],
                 "failed": [{"seed": r["seed"], "error": r["error"]} for r in rs if "error" in r]}
            for k in COUNTS:
                g[k] = int(sum(r[k] for r in ok)) if ok else None
            for grp in groups(plan.tasks):
                keys = sorted({k for r in ok for k in r.get(grp, {})})
                g[grp] = {k: _stats([r[grp].get(k) for r in ok]) for k in keys}
            g["realtime_factor"] = _stats([r.get("realtime_factor") for r in ok])
            for t in (t for t in plan.tasks if t.outcome is not None):
                # how many of these runs' events ended well, of all of them (e.g. crossings stopped for)
                events = [e for r in ok for e in (r[t.name].get(t.outcome.key) or [])]
                g[t.name][t.outcome.key] = {"met": int(sum(events)), "of": len(events)} if events else None
            cells.append(g)
    # the slots and the duration are in the summary's ``settings`` (what the runs were made with)
    return {"seeds": list(plan.seeds), "groups": cells, "environments": environments(results)}
