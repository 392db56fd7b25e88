"""`percept eval`: the closed loop over scenarios x conditions x seeds, locally or on a Ray cluster.

Registered on the main typer app by ``percept.cli.app``; parses options, calls ``percept.drive.batch``, prints.
"""

from __future__ import annotations

from pathlib import Path
from typing import List, Optional

import typer


def _cell(stats: dict | None, key: str = "mean", fmt: str = "{:.3f}") -> str:
    return "n/a" if stats is None else fmt.format(stats[key])


def register(app: typer.Typer) -> None:
    """Add the ``eval`` command to ``app``."""

    @app.command("eval")
    def eval_(
        scenario: List[str] = typer.Option(..., "--scenario", help="Scenario name; repeat for several, or 'all'."),
        seeds: str = typer.Option("0-4", "--seeds", help="Seeds: A-B (inclusive), N, or A,B,C."),
        condition: List[str] = typer.Option(["clear"], "--condition", help="Condition; repeat for several."),
        out: Path = typer.Option(..., "--out", help="Output folder: runs/<scenario>-<condition>-<seed>.json and "
                                                    "summary.json. Runs already there are reused (resume)."),
        workers: int = typer.Option(1, "--workers", help="Parallel runs on this machine (local engine)."),
        engine: str = typer.Option("local", "--engine", help="local | ray."),
        address: Optional[str] = typer.Option(None, "--address", help="Ray cluster address (default: start a "
                                                                      "local Ray)."),
        duration: Optional[float] = typer.Option(None, help="Simulated seconds per run (default: the scenario's own)."),
        lateral: str = typer.Option("privileged", help="Lateral slot: vision | privileged."),
        longitudinal: str = typer.Option("privileged", help="Longitudinal slot: vision | privileged."),
        pedestrians: str = typer.Option("privileged", help="Pedestrian slot: vision | privileged."),
        odometry: str = typer.Option("privileged", help="Odometry slot: vision | privileged."),
        json_path: Optional[Path] = typer.Option(None, "--json", help="Also write the summary to this JSON file."),
    ):
        """Drive every (scenario, condition, seed) and summarise the metrics per scenario and condition.

        Each finished run is written at once, so an interrupted batch keeps its runs and the same command
        resumes it; a run that fails is listed with its error and the others go on.
        """
        from rich import box
        from rich.table import Table

        from percept.cli.app import console, fail, progress_bar, write_json
        from percept.drive.batch import Engine, EvalPlan, evaluate, parse_seeds
        from percept.sims import SCENARIOS

        names = list(SCENARIOS) if scenario == ["all"] else scenario
        if workers < 1:
            fail(f"--workers must be at least 1, got {workers}")
        try:
            eng = Engine(engine)
        except ValueError:
            fail(f"--engine must be local or ray, got '{engine}'")
        try:
            plan = EvalPlan(tuple(names), tuple(condition), tuple(parse_seeds(seeds)),
                            {"lateral": lateral, "longitudinal": longitudinal, "pedestrians": pedestrians,
                             "odometry": odometry}, duration)
            out.mkdir(parents=True, exist_ok=True)
        except ValueError as e:
            fail(str(e))
        except OSError as e:
            fail(f"cannot write {out}: {e.strerror or e}")
        with progress_bar() as bar:
            task = bar.add_task(f"eval {len(plan.jobs)} runs", total=len(plan.jobs))
            try:
                summary = evaluate(plan, out, workers, eng, address, progress=lambda r: bar.advance(task))
            except RuntimeError as e:
                fail(str(e))
        t = Table(title=f"{len(plan.jobs)} runs, lateral {lateral}", box=box.SIMPLE_HEAD, pad_edge=False,
                  collapse_padding=True,
                  caption="lane errors (offset m, heading rad, curvature 1/m) and centering RMS (m): means over "
                          "seeds; centering max (m): the worst run")
        for col in ("scenario", "cond", "runs", "coll", "dep", "offset", "head", "curv", "c.rms", "c.max"):
            t.add_column(col, justify="left" if col in ("scenario", "cond") else "right", no_wrap=True)
        for g in summary["groups"]:
            lane = g["lane"]
            t.add_row(g["scenario"], g["condition"], str(len(g["seeds"])), str(g["collisions"]),
                      str(g["lane_departures"]), _cell(lane.get("offset_rmse_m"), fmt="{:.4f}"),
                      _cell(lane.get("heading_rmse_rad"), fmt="{:.4f}"), _cell(lane.get("curvature_rmse_1pm"),
                                                                                fmt="{:.5f}"),
                      _cell(lane.get("centering_rms_m")), _cell(lane.get("centering_max_m"), "max"))
        console.print(t)
        console.print(f"all metrics per scenario and condition (mean / max / min): {out / 'summary.json'}")
        for g in summary["groups"]:
            for f in g["failed"]:
                console.print(f"[red]failed[/] {g['scenario']}/{g['condition']}/seed {f['seed']}: {f['error']}")
        write_json(json_path, summary)
