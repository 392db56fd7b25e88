"""Evaluation reports: summary.csv / summary.md / plots from run JSONs, and `percept eval --strict`."""

import csv
import io
from types import SimpleNamespace

import cv2
import numpy as np
from typer.testing import CliRunner

from percept.cli import app
from percept.drive.tasks import TASKS
from percept.evaluate import batch as ev
from percept.evaluate.report import (listed_runs, metric_rows, reproduce_command, summary_csv, unsafe_runs,
                                  write_reports)

runner = CliRunner()
SETTINGS = {"percept": "0.1.0", "duration_s": 12.0, "detector": None, "lane_changes": True,
            "slots": {"lanes": "vision", "longitudinal": "privileged", "pedestrians": "privileged",
                      "odometry": "privileged"}}


def run(seed, collisions=0, recall=None, offset=0.01, stops=None, phantom=0, traj=False, ate=0.1):
    odo = {"ate_rmse_fused_m": None}
    if traj:
        odo = {"ate_rmse_fused_m": 0.1, "ate_rmse_landmarks_m": ate,
               "trajectory": {"every_frames": 15, "true": [[0, 0], [10, 0], [20, 1]],
                              "estimate": [[0, 0], [10, 0.1], [20, 1.2]]}}
    return {"scenario": "highway", "condition": "clear", "seed": seed, "frames": 10, "collisions": collisions,
            "pedestrian_collisions": 0, "lane_departures": 0, "unsafe_lane_changes": 0, "realtime_factor": 2.0 + seed,
            "lanes": {"offset_rmse_m": offset, "centering_rms_m": 0.05},
            "longitudinal": {"phantom_brakes": phantom, "range_abs_rel_err_by_bin": {"0-20": 0.01, "20-40": 0.02}},
            "pedestrians": {"recall": recall, "stops": stops}, "odometry": odo, "timing_ms": {"lanes": 1.0}}


PLAN = SimpleNamespace(scenarios=("highway",), conditions=("clear",), seeds=(0, 1, 2, 3), tasks=TASKS)


def test_rows_have_mean_p95_and_the_worst_on_the_right_side():
    runs = [run(k, recall=r, offset=o, stops=s, phantom=k % 2)
            for k, (r, o, s) in enumerate([(0.9, 0.01, [True]), (0.5, 0.02, [False]), (0.8, 0.04, [True]),
                                           (0.7, 0.03, [True, False])])]
    rows = {r["metric"]: r for r in metric_rows(PLAN, runs, TASKS)}
    assert rows["lanes.offset_rmse_m"]["worst"] == 0.04 and rows["lanes.offset_rmse_m"]["better"] == "lower"
    assert rows["pedestrians.recall"]["worst"] == 0.5 and rows["pedestrians.recall"]["better"] == "higher"
    assert rows["pedestrians.recall"]["p95"] == np.percentile([0.9, 0.5, 0.8, 0.7], 5)
    assert rows["realtime_factor"]["worst"] == 2.0  # slowest run
    assert rows["missed_stops"]["total"] == 2 and rows["phantom_brakes"]["total"] == 2
    assert rows["lanes.offset_rmse_m"]["total"] is None  # only counts are summed
    back = list(csv.DictReader(io.StringIO(summary_csv(list(rows.values())))))
    assert {r["metric"] for r in back} == set(rows) and back[0]["scenario"] == "highway"


def test_unsafe_runs_come_with_the_command_that_reproduces_them():
    runs = [run(0), run(1, collisions=2), {"scenario": "highway", "condition": "clear", "seed": 2, "error": "x"}]
    bad = unsafe_runs(runs)
    assert [(r["seed"], what) for r, what in bad] == [(1, "2 collisions")]
    assert reproduce_command(bad[0][0], SETTINGS) == ("percept drive --scenario highway --seed 1 --condition clear "
                                                      "--longitudinal privileged --pedestrians privileged "
                                                      "--odometry privileged --duration 12")
    every = {**SETTINGS, "slots": {k: "privileged" for k in SETTINGS["slots"]}}
    assert reproduce_command(bad[0][0], every).endswith("--condition clear --privileged --duration 12")
    vision = {**SETTINGS, "slots": {k: "vision" for k in SETTINGS["slots"]}, "detector": "inria"}
    assert reproduce_command(bad[0][0], vision).endswith("--condition clear --duration 12 --detector inria")
    assert reproduce_command(bad[0][0], {**vision, "rear": True}).endswith("--detector inria --rear")
    assert reproduce_command(bad[0][0], {**SETTINGS, "rear": False}).endswith("--duration 12 --no-rear")
    # lane changes are on by default; a batch that kept its lane, or predates the option, says so
    assert reproduce_command(bad[0][0], {**SETTINGS, "lane_changes": False}).endswith("--lane-changes off")
    legacy = {k: v for k, v in SETTINGS.items() if k != "lane_changes"}
    assert reproduce_command(bad[0][0], legacy).endswith("--lane-changes off")


def test_stops_for_no_one_are_listed_and_summed_but_do_not_fail_strict(tmp_path):
    ghost = run(1)
    ghost["pedestrians"].update(false_stops=1, brakes_for_no_one=2)
    runs = [run(0), ghost]
    assert unsafe_runs(runs) == []
    assert [(r["seed"], what) for r, what in listed_runs(runs, TASKS)] == [(1, "1 false stops, 2 brakes for no one")]
    rows = {r["metric"]: r for r in metric_rows(PLAN, runs, TASKS)}
    assert rows["false_stops"]["total"] == 1 and rows["brakes_for_no_one"]["total"] == 2
    write_reports(PLAN, runs, SETTINGS, tmp_path, TASKS)
    md = (tmp_path / "summary.md").read_text()
    assert "| highway | clear | 2 | 0 | 0 | 0 | 0 | 0 | 0 | 0 | 1 | 2 |" in md
    assert "seed 1: 1 false stops, 2 brakes for no one — `percept drive --scenario highway --seed 1" in md


def test_reports_are_written_and_readable(tmp_path):
    runs = [run(k, recall=0.8, traj=k < 2, ate=0.5 if k == 1 else 0.1) for k in range(4)] + [run(4, collisions=1)]
    written = write_reports(PLAN, runs, SETTINGS, tmp_path, TASKS)
    md = (tmp_path / "summary.md").read_text()
    assert "| highway | clear | 5 | 0 | 1 | 0 | 0 | 0 | 0 | 0 | 0 |" in md  # the safety totals
    # these runs carry no environment (as an older percept's): said so, not invented
    assert "Environment not recorded: 5 runs" in md
    assert "seed 4: 1 collisions" in md and "`percept drive --scenario highway --seed 4" in md
    pngs = [p for p in written if p.suffix == ".png"]
    names = {p.name for p in pngs}
    assert {"lanes.centering_rms_m.png", "longitudinal.range_error_by_range.highway.png",
            "odometry.trajectory.highway-clear-1.png"} <= names
    # one trajectory per scenario and condition: the run with the worst ATE
    assert not any(n.startswith("odometry.trajectory.highway-clear-0") for n in names)
    for p in pngs:
        img = cv2.imread(str(p))
        assert img is not None and img.shape[2] == 3 and img.std() > 5  # something is drawn
        assert f"plots/{p.name}" in md


def test_strict_lists_unsafe_runs_and_exits_1(tmp_path, monkeypatch):
    monkeypatch.setattr(ev, "run_drive", lambda cfg, render=True: {
        **run(cfg.world.seed, collisions=int(cfg.world.seed == 1)), "scenario": cfg.world.scenario})
    args = ["eval", "--scenario", "highway", "--seeds", "0-2", "--out", str(tmp_path)]
    r = runner.invoke(app, args + ["--strict"])
    assert r.exit_code == 1
    assert "unsafe highway/clear/seed 1: 1 collisions; reproduce: percept drive --scenario highway --seed 1" in r.output
    assert (tmp_path / "summary.md").exists() and (tmp_path / "summary.csv").exists()
    assert runner.invoke(app, args).exit_code == 0  # without --strict the same batch is a success


def test_the_eval_tables_fit_an_80_column_terminal():
    from rich.console import Console

    from percept.cli.eval_cmd import summary_tables

    runs = [run(k, recall=0.8, offset=0.0123, stops=[True], traj=True) for k in range(4)]
    summary = {**ev.summarize(PLAN, runs), "settings": SETTINGS}
    console = Console(width=80, record=True, file=io.StringIO())
    console.print(summary_tables(summary, TASKS))
    lines = console.export_text().splitlines()
    assert max(len(line) for line in lines) <= 80
    # each task with a metric some run has gets its table, every value on the scenario's line, none cut
    rows = [line for line in lines if line.split()[:2] == ["highway", "clear"]]
    assert len(rows) == 5 and "0.0123" in rows[1] and "0.800" in rows[3]
    assert all(line.rstrip()[-1].isdigit() or line.rstrip().endswith("n/a") for line in rows)


def test_plots_an_earlier_batch_drew_and_this_one_does_not_are_removed(tmp_path):
    stale = tmp_path / "plots" / "odometry.trajectory.loop-night-7.png"
    stale.parent.mkdir()
    stale.write_bytes(b"an earlier batch's plot")
    notes = tmp_path / "plots" / "notes.txt"  # not a plot: left alone
    notes.write_text("kept")
    written = write_reports(PLAN, [run(k) for k in range(4)], SETTINGS, tmp_path, TASKS)
    assert not stale.exists() and notes.read_text() == "kept"
    assert sorted(tmp_path.glob("plots/*.png")) == sorted(p for p in written if p.suffix == ".png")
