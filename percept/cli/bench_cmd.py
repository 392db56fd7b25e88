"""`percept bench`: per-stage cost on one thread against the named peers, in one run."""

from __future__ import annotations

from typing import Annotated

import typer
from rich.table import Table

from . import options as opt
from .common import check_outputs, console, fmt, progress_bar, write_json


def bench(
    json_path: opt.JsonOut = None,
    frames: Annotated[int, typer.Option("--frames", help="Timed calls per stage, 1 to 10,000 (slots: the median "
                                                         "of 3 passes' means over consecutive frames; render "
                                                         "and peers: the median).")] = 30,
):
    """Per-stage cost on one thread (stages named by the run JSON's timing_ms keys), against the named peers
    measured in the same run (ratio = ours / peer)."""
    from threadpoolctl import threadpool_limits

    from percept.drive import TASKS
    from percept.drive.bench import bench_render, bench_task, bench_ticks

    opt.check_number("--frames", frames, 1, 10000)
    check_outputs([json_path])
    tasks = [t for t in TASKS if t.vision is not None]
    # one thread: OpenCV's is set per stage, numpy's BLAS here
    with progress_bar() as bar, threadpool_limits(1):
        peers = sum(t.bench_peer is not None for t in tasks)
        task = bar.add_task("benchmarking", total=bench_ticks(frames, len(tasks), peers))
        tick = lambda: bar.advance(task)  # noqa: E731
        results = [bench_render(frames, progress=tick)] + [bench_task(t, TASKS, frames, progress=tick)
                                                           for t in tasks]
    t = Table(title="percept bench (one thread, ms per call: slots the median of 3 passes' means over consecutive "
                    "frames, the rest the median)")
    for col in ("stage", "what", "ms", "target ms", "peer", "peer ms", "ratio"):
        t.add_column(col, justify="left" if col in ("stage", "what", "peer") else "right")
    for r in results:
        t.add_row(r.stage, r.what, f"{r.ms:.2f}", fmt(r.target_ms), r.peer or "-", fmt(r.peer_ms), fmt(r.ratio))
    console.print(t)
    write_json(json_path, {"stages": [r.to_dict() for r in results]})
