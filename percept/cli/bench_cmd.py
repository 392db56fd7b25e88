"""`percept bench`: per-stage cost on one thread against the named peers, in one run."""

from __future__ import annotations

from typing import Annotated, List, Optional

import typer
from rich import box
from rich.console import Group
from rich.table import Table

from . import options as opt
from .common import check_outputs, console, fail, fmt, progress_bar, write_json


def bench(
    json_path: opt.JsonOut = None,
    frames: Annotated[int, typer.Option("--frames", help="Timed calls per stage, 1 to 10,000 (slots: the median "
                                                         "of 3 passes' means over consecutive frames; render "
                                                         "and peers: the median).")] = 30,
    stack: Annotated[bool, opt.flag("--stack", help="Also the whole stack: every vision slot in the closed loop on "
                                                    "each scenario (both rigs) beside the stock composition of the peers, "
                                                    "both stereo pairs alone on each scenario, the render cost per "
                                                    "condition, the realtime factor with and without "
                                                    "recording.")] = False,
    scenario: Annotated[Optional[List[str]], typer.Option("--scenario", help="With --stack: only these scenarios "
                                                          "(repeat; default every one).")] = None,
    seconds: Annotated[float, typer.Option("--seconds", help="With --stack: simulated seconds of each closed loop, "
                                                             "1 to 600.")] = 10.0,
    repeats: Annotated[int, typer.Option("--repeats", help="With --stack: closed loops per scenario without and "
                                                           "with recording, alternating, 1 to 20 (the table shows "
                                                           "the median and the range).")] = 3,
    soak_minutes: Annotated[float, typer.Option("--soak-minutes", help="Also a recorded closed loop (highway, "
                                                "every slot on vision) this many simulated minutes long, 0 to 600, "
                                                "with the process's memory each minute (0: none).")] = 0.0,
):
    """Per-stage cost on one thread (stages named by the run JSON's timing_ms keys), against the named peers
    measured in the same run (ratio = ours / peer)."""
    from threadpoolctl import threadpool_limits

    from percept.bench.stages import bench_render, bench_task, bench_ticks
    from percept.drive.tasks import TASKS

    opt.check_number("--frames", frames, 1, 10000)
    opt.check_number("--seconds", seconds, 1, 600)
    opt.check_number("--repeats", repeats, 1, 20)
    opt.check_number("--soak-minutes", soak_minutes, 0, 600)
    if scenario and not stack:
        fail("--scenario chooses the scenarios of the whole stack: add --stack")
    scenarios = _scenarios(scenario) if stack else []
    check_outputs([json_path])
    tasks = [t for t in TASKS if t.vision is not None]
    # one thread: OpenCV's is set per stage, numpy's BLAS here
    with progress_bar() as bar, threadpool_limits(1):
        peers = sum(t.bench_peer is not None for t in tasks)
        task = bar.add_task("benchmarking", total=bench_ticks(frames, len(tasks), peers))
        tick = lambda: bar.advance(task)  # noqa: E731
        results = [bench_render(frames, progress=tick)] + [bench_task(t, TASKS, frames, progress=tick)
                                                           for t in tasks]
    console.print(_stage_table(results))
    console.print(_stage_legend(results), highlight=False)
    out = {"stages": [r.to_dict() for r in results]}
    if stack or soak_minutes:
        out.update(_stack(scenarios, seconds, repeats, soak_minutes))
    write_json(json_path, out)


def _stage_table(results) -> Table:
    """One row per stage, narrow enough for an 80-column terminal: what each stage and peer is follows below it
    (``_stage_legend``)."""
    t = Table(title="percept bench: one thread, ms per call (slots: median of 3 passes' means over consecutive "
                    "frames; the rest: median)", box=box.SIMPLE_HEAD, title_justify="left")
    for col in ("stage", "ms", "peer ms", "against the peer", "target", "met"):
        t.add_column(col, justify="left" if col in ("stage", "target") else "right", no_wrap=True)
    for r in results:
        t.add_row(r.stage, f"{r.ms:.2f}", fmt(r.peer_ms), speed_text(r.ratio), target_text(r),
                  "-" if r.met is None else ("yes" if r.met else "NO"))
    return t


def _stage_legend(results) -> str:
    """Each stage's work and its peer, a line each."""
    return "\n".join(f"  {r.stage}: {r.what}" + (f"; peer: {r.peer}" if r.peer else "") for r in results)


def target_text(r) -> str:
    """A stage's targets as a person reads them: '<= 3 ms, >= 15x', or '-'."""
    parts = ([] if r.target_ms is None else [f"<= {r.target_ms:g} ms"]) + (
        [] if r.target_speedup is None else [f">= {r.target_speedup:g}x"])
    return ", ".join(parts) or "-"


def speed_text(ratio: float | None) -> str:
    """The JSON's ratio (ours / peer) as a person reads it: '40.0x faster', '3.6x slower', 'n/a'."""
    if ratio is None or not ratio > 0:
        return "n/a"
    return f"{1 / ratio:.1f}x faster" if ratio < 1 else f"{ratio:.1f}x slower"


def _scenarios(names: list[str] | None) -> list[str]:
    """The --scenario names, checked (every scenario when none is given); a one-line error on an unknown one."""
    from percept.sims import SCENARIOS, check_scenario

    try:
        for n in names or []:
            check_scenario(n)
    except ValueError as e:
        fail(str(e))
    return list(names) if names else list(SCENARIOS)


def _stack(scenarios: list[str], seconds: float, repeats: int, soak_minutes: float) -> dict:
    """The whole stack per scenario, the render per condition and the soak, printed and as the JSON's groups."""
    from percept.bench.stack import CONDITIONS, PAIR_FRAMES, bench_stack, render_per_condition, soak
    from percept.sensors.frame import FRAME_RATE_HZ

    loop_frames = int(round(seconds * FRAME_RATE_HZ))
    total = 2 * repeats * loop_frames * len(scenarios) + int(round(soak_minutes * 60 * FRAME_RATE_HZ))
    with progress_bar() as bar:
        task = bar.add_task("the whole stack", total=total)
        tick = lambda: bar.advance(task)  # noqa: E731
        stacks = [bench_stack(sc, seconds, repeats=repeats, progress=tick) for sc in scenarios]
        conditions = render_per_condition() if scenarios else {}
        soaked = soak(soak_minutes, progress=tick) if soak_minutes else None
    out = {}
    if stacks:
        console.print(_stack_tables(stacks, repeats))
        console.print(f"both stereo pairs alone on each scenario (clear, ms, the median of {PAIR_FRAMES} frames; "
                      "\"render\" above is the closed loop's mean): " + ", ".join(f"{c.scenario} {fmt(c.stereo_pair_ms)}"
                                                                     for c in stacks))
        console.print("stereo pair with each condition (highway, ms): " + ", ".join(
            f"{k} {fmt(conditions[k])}" for k in CONDITIONS))
        console.print(_stack_targets(stacks))
        out.update({"stack": [c.to_dict() for c in stacks],
                    "render_conditions_ms": {k: round(v, 3) for k, v in conditions.items()}})
    if soaked:
        console.print(f"soak: {soaked['minutes']:g} simulated minutes recorded, memory each minute "
                      f"{soaked['rss_mb']} MB (peak {soaked['peak_mb']}, growth {soaked['growth_mb']}, after the first "
                      f"minute {fmt(soaked['mb_per_minute'])} MB a minute), realtime "
                      f"{soaked['realtime_factor']}")
        out["soak"] = soaked
    return out


def _stack_tables(stacks, repeats: int) -> Group:
    """The whole stack per scenario, in two tables that each fit 80 columns: each stage's cost; then the stock
    composition, the speed-up and the realtime factors."""
    from percept.drive.tasks import TASKS

    keys = ["render"] + [t.name for t in TASKS if t.vision is not None] + ["perception_total"]
    cost = Table(title=f"the whole stack on vision in the closed loop: ms per frame, one thread, the median of "
                       f"{repeats} drives", box=box.SIMPLE_HEAD, title_justify="left")
    cost.add_column("scenario", no_wrap=True)
    for k in keys:
        cost.add_column(k.replace("_", " ").replace("perception total", "total"), justify="right", no_wrap=True)
    for c in stacks:
        cost.add_row(c.scenario, *(fmt(c.timing_ms.get(k)) for k in keys))
    peers = " + ".join(t.name for t in TASKS if t.bench_peer is not None)
    speed = Table(title=f"against the stock composition (the peers of {peers}, ms per frame); times real time: "
                        "the median drive, the median and the slowest recorded one", box=box.SIMPLE_HEAD,
                  title_justify="left")
    for col in ("scenario", "stock", "faster", "top-down", "realtime", "recorded", "slowest"):
        speed.add_column(col, justify="left" if col == "scenario" else "right", no_wrap=True)
    for c in stacks:
        speed.add_row(c.scenario, fmt(c.stock_ms), fmt(c.speedup), fmt(c.peers_ms["render"]),
                      fmt(c.realtime_factor), fmt(c.realtime_factor_recording),
                      fmt(min(c.realtime_factors_recording, default=None)))
    return Group(cost, speed)


def _stack_targets(stacks) -> str:
    """On how many scenarios each of the stack's targets was kept in this run, as one line."""
    from percept.bench.stack import TARGETS

    parts = []
    for key, name in TARGETS.items():
        kept = [c.met[key] for c in stacks if c.met[key] is not None]
        parts.append(f"{name}: {sum(kept)} of {len(kept)} scenarios")
    return "targets kept: " + "; ".join(parts)
