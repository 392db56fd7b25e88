"""Batch evaluation: `percept eval` through CliRunner, resume, failures, bad input."""

import json
import sys

import pytest
from typer.testing import CliRunner

from percept.cli import app
from percept.cli import options as opt
from percept.evaluate import batch as ev
from percept.evaluate import EvalPlan, Job, parse_seeds

runner = CliRunner()


def test_parse_seeds():
    assert parse_seeds("0-3") == [0, 1, 2, 3]
    assert parse_seeds("7") == [7]
    assert parse_seeds("5,1-2,1") == [1, 2, 5]
    for bad in ("3-1", "a", "-2", "1-", ""):
        with pytest.raises(ValueError, match="--seeds must look like"):
            parse_seeds(bad)


def test_parse_seeds_counts_a_range_before_expanding_it():
    """'0-99999999999' once took all memory (the range was expanded first); now it is refused at once."""
    with pytest.raises(ValueError, match="--seeds go from 0 to 2147483647, got 99999999999"):
        parse_seeds("0-99999999999")
    with pytest.raises(ValueError, match="names 20001 seeds; a batch takes at most 10000"):
        parse_seeds("0-20000")
    assert len(parse_seeds("0-6000,3000-9999,9999")) == ev.MAX_SEEDS  # overlaps counted once
    with pytest.raises(ValueError, match="names 10001 seeds"):
        parse_seeds("0-6000,3000-10000")
    assert ev.MAX_SEED == opt.MAX_SEED  # eval's seeds and drive's --seed have one bound


@pytest.mark.slow
def test_eval_writes_runs_and_a_summary_and_resumes(tmp_path):
    args = ["eval", "--scenario", "lead-brake", "--scenario", "cut-in", "--seeds", "0-1", "--duration", "2",
            "--privileged", "--out", str(tmp_path), "--json", str(tmp_path / "s.json")]
    r = runner.invoke(app, args)
    assert r.exit_code == 0, r.output
    runs = sorted(p.name for p in (tmp_path / "runs").iterdir())
    assert runs == ["cut-in-clear-0.json", "cut-in-clear-1.json", "lead-brake-clear-0.json", "lead-brake-clear-1.json"]
    s = json.loads((tmp_path / "summary.json").read_text())
    assert s == json.loads((tmp_path / "s.json").read_text())
    g = {(x["scenario"], x["condition"]): x for x in s["groups"]}
    lb = g[("lead-brake", "clear")]
    assert lb["seeds"] == [0, 1] and lb["failed"] == [] and lb["collisions"] == 0
    one = [json.loads((tmp_path / "runs" / f"lead-brake-clear-{k}.json").read_text()) for k in (0, 1)]
    gaps = [x["longitudinal"]["time_gap_min_s"] for x in one]
    assert lb["longitudinal"]["time_gap_min_s"] == pytest.approx({"mean": sum(gaps) / 2, "max": max(gaps),
                                                                  "min": min(gaps)})
    # a metric no run has stays null; privileged lanes has no estimate to score
    assert lb["lanes"]["offset_rmse_m"] is None and lb["pedestrians"]["stops"] is None
    # each run records what its numbers depend on besides the code, and the summary lists where the runs came from
    import numpy as np

    env = one[0]["environment"]
    assert env["numpy"] == np.__version__ and env["blas"] and env["opencv_cpu"] and env["cpu"]
    assert s["environments"] == [{**env, "runs": 4}]
    md = (tmp_path / "summary.md").read_text()
    assert f"numpy {np.__version__}" in md and "4 runs." in md
    # the same command again reuses the finished runs instead of driving them again
    stamp = {p: p.stat().st_mtime_ns for p in (tmp_path / "runs").iterdir()}
    r = runner.invoke(app, args)
    assert r.exit_code == 0, r.output
    assert {p: p.stat().st_mtime_ns for p in (tmp_path / "runs").iterdir()} == stamp


@pytest.fixture
def seed_1_crashes(monkeypatch):
    """Every run with seed 1 raises RuntimeError("simulated crash")."""
    real = ev.run_drive

    def flaky(cfg, render=True):
        if cfg.world.seed == 1:
            raise RuntimeError("simulated crash")
        return real(cfg, render=render)

    monkeypatch.setattr(ev, "run_drive", flaky)


@pytest.mark.slow
def test_a_failing_run_is_reported_and_the_others_are_kept(tmp_path, seed_1_crashes):
    plan = EvalPlan(("lead-brake",), ("clear",), (0, 1, 2), duration_s=1.0, default="privileged")
    s = ev.evaluate(plan, tmp_path)
    g = s["groups"][0]
    assert g["seeds"] == [0, 2]
    assert g["failed"] == [{"seed": 1, "error": "RuntimeError: simulated crash"}]
    assert sorted(p.name for p in (tmp_path / "runs").iterdir()) == ["lead-brake-clear-0.json",
                                                                     "lead-brake-clear-2.json"]


@pytest.mark.slow
def test_a_resumed_batch_reports_only_the_runs_it_drives(tmp_path, seed_1_crashes):
    plan = EvalPlan(("lead-brake",), ("clear",), (0, 1, 2), duration_s=1.0, default="privileged")
    ev.evaluate(plan, tmp_path)
    seen = []
    ev.evaluate(plan, tmp_path, progress=seen.append)
    # seeds 0 and 2 are reused (the bar starts with them done), seed 1 failed and is driven again
    assert len(seen) == 1 and "simulated crash" in seen[0]["error"]


def test_time_left_is_the_mean_pace_not_the_last_30_seconds():
    import io

    from rich.console import Console
    from rich.progress import Progress, TimeRemainingColumn

    from percept.cli.common import MeanPaceRemaining

    clock = [0.0]
    bar = Progress(get_time=lambda: clock[0], auto_refresh=False, console=Console(file=io.StringIO()))
    task = bar.add_task("eval", total=10, completed=4, start_completed=4)  # 4 runs reused
    ours, rich_own = MeanPaceRemaining(), TimeRemainingColumn()
    assert ours.render(bar.tasks[0]).plain == "-:--:--"
    # two workers: a run a minute each, finishing together
    for t in (60.0, 61.0):
        clock[0] = t
        bar.advance(task, 1)
    # 2 runs in 61 s, 4 left: 122 s; Rich's own column read the pair as a run a second
    assert ours.render(bar.tasks[0]).plain == "0:02:02"
    assert rich_own.render(bar.tasks[0]).plain == "0:00:04"


@pytest.mark.slow
def test_parallel_workers_give_the_same_metrics_as_one(tmp_path):
    plan = EvalPlan(("cut-in",), ("clear",), (0, 1), duration_s=2.0, default="privileged")
    a = ev.evaluate(plan, tmp_path / "a", workers=1)
    b = ev.evaluate(plan, tmp_path / "b", workers=2)
    for s in (a, b):
        s["groups"][0].pop("timing_ms")
        s["groups"][0].pop("realtime_factor")
    assert a == b


@pytest.mark.parametrize("args, message", [
    (["--scenario", "nowhere"], "unknown scenario"),
    (["--scenario", "highway", "--seeds", "9-1"], "--seeds must look like"),
    (["--scenario", "highway", "--workers", "0"], "--workers must be a finite number between 1 and 256"),
    (["--scenario", "highway", "--engine", "spark"], "--engine must be local or ray"),
    (["--scenario", "highway", "--condition", "fog"], "condition"),
    (["--scenario", "highway", "--duration", "inf"], "--duration must be a finite number"),
    (["--scenario", "highway", "--duration", "0"], "--duration must be a finite number"),
    (["--scenario", "highway", "--duration", "1e308"], "--duration must be a finite number"),
    (["--scenario", "highway", "--workers", "99999999999"], "--workers must be a finite number between 1 and 256"),
    (["--scenario", "highway", "--seeds", "0-99999999999"], "--seeds go from 0 to 2147483647"),
    (["--scenario", "all", "--scenario", "highway"], "--scenario all already means every scenario"),
    (["--scenario", "all", "--scenario", "nowhere"], "--scenario all already means every scenario"),
])
def test_eval_bad_input_is_one_line_exit_2(tmp_path, args, message, one_line_error):
    one_line_error(runner.invoke(app, ["eval", "--out", str(tmp_path / "o"), *args]), message)
    assert not (tmp_path / "o" / "summary.json").exists()


@pytest.mark.slow
def test_ray_engine_gives_the_local_engine_s_runs(tmp_path):
    import ray

    plan = EvalPlan(("cut-in",), ("clear",), (0, 1), duration_s=2.0, default="privileged")
    try:
        ray.init(num_cpus=2, include_dashboard=False, logging_level="ERROR", log_to_driver=False)
        a = ev.evaluate(plan, tmp_path / "ray", engine=ev.Engine.RAY)
    finally:
        ray.shutdown()
    b = ev.evaluate(plan, tmp_path / "local")
    for s in (a, b):
        s["groups"][0].pop("timing_ms")
        s["groups"][0].pop("realtime_factor")
    assert a == b and a["groups"][0]["seeds"] == [0, 1]
    assert sorted(p.name for p in (tmp_path / "ray" / "runs").iterdir()) == ["cut-in-clear-0.json",
                                                                            "cut-in-clear-1.json"]


def test_ray_engine_without_ray_says_how_to_get_it(tmp_path, monkeypatch, one_line_error):
    monkeypatch.setitem(sys.modules, "ray", None)  # import ray -> ImportError
    r = runner.invoke(app, ["eval", "--scenario", "highway", "--seeds", "0", "--duration", "1", "--engine", "ray",
                            "--out", str(tmp_path)])
    one_line_error(r, "pip install 'percept[ray]'")


def test_jobs_cover_the_plan():
    plan = EvalPlan(("highway", "curves"), ("clear", "rain"), (0, 1, 2), default="privileged")
    assert len(plan.jobs) == 12 and Job("curves", "rain", 2) in plan.jobs


def test_the_people_model_is_a_setting_only_where_the_pedestrian_slot_sees():
    from percept.evaluate.resume import run_settings

    sim = EvalPlan(("crossing",), ("clear",), (0,), {"pedestrians": "vision"}, default="privileged")
    inria = EvalPlan(("crossing",), ("clear",), (0,), {"pedestrians": "vision"}, detector="inria",
                     default="privileged")
    assert run_settings(sim)["detector"] == "sim" and run_settings(inria)["detector"] == "inria"
    assert run_settings(EvalPlan(("crossing",), ("clear",), (0,), default="privileged"))["detector"] is None
    with pytest.raises(ValueError, match="--detector must be"):
        EvalPlan(("crossing",), ("clear",), (0,), {"pedestrians": "vision"}, detector="missing.npz",
                 default="privileged")


def _files(folder) -> dict:
    return {p.name: p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.mark.slow
def test_resume_never_mixes_runs_made_with_other_settings(tmp_path, one_line_error):
    base = ["eval", "--scenario", "lead-brake", "--scenario", "lead-brake", "--seeds", "0", "--out", str(tmp_path)]
    r = runner.invoke(app, [*base, "--duration", "2"])
    assert r.exit_code == 0, r.output
    assert [p.name for p in (tmp_path / "runs").iterdir()] == ["lead-brake-clear-0.json"]  # duplicates dropped
    run = json.loads((tmp_path / "runs" / "lead-brake-clear-0.json").read_text())
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert run["settings"] == summary["settings"] and run["settings"]["duration_s"] == 2.0
    assert run["settings"]["slots"]["lanes"] == "vision" and run["settings"]["percept"]
    before = _files(tmp_path)
    for args, diff in ((["--duration", "1"], "duration_s 2.0 (now 1.0)"),
                       (["--duration", "2", "--lanes", "privileged"], "slots lanes=vision (now privileged)")):
        r = runner.invoke(app, [*base, *args])
        one_line_error(r, "made with other settings")
        assert diff in r.output and "--redo" in r.output
        assert _files(tmp_path) == before  # refused before any work
    r = runner.invoke(app, [*base, "--duration", "1", "--redo"])
    assert r.exit_code == 0, r.output
    run = json.loads((tmp_path / "runs" / "lead-brake-clear-0.json").read_text())
    assert run["settings"]["duration_s"] == 1.0 and run["duration_s"] == 1.0


@pytest.mark.slow
def test_damaged_run_files_are_listed_and_redone(tmp_path, one_line_error):
    args = ["eval", "--scenario", "lead-brake", "--seeds", "0-3", "--duration", "1", "--out", str(tmp_path)]
    runs = tmp_path / "runs"
    runs.mkdir()
    (runs / "lead-brake-clear-0.json").write_text('{"scenario": "lead-br')
    (runs / "lead-brake-clear-1.json").write_text("")
    (runs / "lead-brake-clear-2.json").write_text('{"hello": "world"}')
    (runs / "lead-brake-clear-3.json").write_bytes(b"\xff\xfe\x00")
    r = runner.invoke(app, args)
    assert r.exit_code == 0, r.output
    lines = [ln for ln in r.output.splitlines() if ln.startswith("redoing")]
    assert len(lines) == 4 and "Traceback" not in r.output
    assert "not JSON" in lines[0] and "empty" in lines[1] and "not a percept run" in lines[2]
    assert all(json.loads(p.read_text())["frames"] == 15 for p in runs.iterdir())
    # a hand-edited run without its counts (once a KeyError in the summary) is damaged too
    edited = json.loads((runs / "lead-brake-clear-1.json").read_text())
    del edited["collisions"]
    edited["pedestrians"] = None
    (runs / "lead-brake-clear-1.json").write_text(json.dumps(edited))
    r = runner.invoke(app, args)
    assert r.exit_code == 0 and "Traceback" not in r.output, r.output
    assert "redoing" in r.output and "no valid collisions, pedestrians" in r.output
    assert "collisions" in json.loads((runs / "lead-brake-clear-1.json").read_text())
    (runs / "lead-brake-clear-0.json").unlink()
    (runs / "lead-brake-clear-0.json").mkdir()
    one_line_error(runner.invoke(app, args), "is a folder where a run file belongs")


@pytest.mark.slow
def test_eval_exits_1_and_says_how_many_runs_failed(tmp_path, seed_1_crashes):
    r = runner.invoke(app, ["eval", "--scenario", "lead-brake", "--seeds", "0-1", "--duration", "1",
                            "--out", str(tmp_path), "--json", str(tmp_path / "s.json")])
    assert r.exit_code == 1
    assert "1 of 2 runs failed" in r.output and "RuntimeError: simulated crash" in r.output
    assert json.loads((tmp_path / "s.json").read_text())["groups"][0]["failed"][0]["seed"] == 1
    assert [p.name for p in (tmp_path / "runs").iterdir()] == ["lead-brake-clear-0.json"]
