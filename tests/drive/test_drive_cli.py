"""`percept drive` through typer's CliRunner: contract, recording, bad input."""

import json
import subprocess

import pytest
from typer.testing import CliRunner

from percept.cli import app
from percept.drive.tasks import TASKS
from percept.cli.view_cmd import rerun_executable

runner = CliRunner()
KEYS = ["scenario", "condition", "seed", "duration_s", "frames", "realtime_factor", "collisions",
        "pedestrian_collisions", "lane_departures", "unsafe_lane_changes", "lanes", "longitudinal", "pedestrians",
        "odometry", "timing_ms", "progress", "lane_changes", "evasive"]


def rerun_bin() -> str:
    return rerun_executable()


@pytest.mark.slow
def test_drive_records_a_valid_rrd_and_writes_the_json(tmp_path):
    rrd, js = tmp_path / "run.rrd", tmp_path / "run.json"
    r = runner.invoke(app, ["drive", "--duration", "1", "--record", str(rrd), "--json", str(js)])
    assert r.exit_code == 0, r.output
    d = json.loads(js.read_text())
    for k in KEYS:
        assert k in d
    assert d["scenario"] == "highway" and d["frames"] == 15
    assert d["timing_ms"]["render"] > 0
    # every slot sees by default, and each one's stage is timed
    assert d["slots"] == {t.name: "vision" for t in TASKS}
    assert d["lane_changes_on"]  # the lane-change law runs by default
    assert all(d["timing_ms"][t.name] > 0 for t in TASKS)
    assert rrd.exists() and not (tmp_path / "run.rrd.part").exists()
    # a finished recording passes Rerun's own check as it is, footer included
    v = subprocess.run([rerun_bin(), "rrd", "verify", str(rrd)], capture_output=True, text=True,
                       env={"RERUN_ANALYTICS": "0", "PATH": ""})
    assert v.returncode == 0, v.stdout + v.stderr


def test_vision_lanes_recording_shows_what_the_lanes_module_saw(tmp_path):
    rrd = tmp_path / "v.rrd"
    r = runner.invoke(app, ["drive", "--scenario", "curves", "--duration", "1", "--lanes", "vision",
                            "--record", str(rrd), "--json", str(tmp_path / "v.json")])
    assert r.exit_code == 0, r.output
    p = subprocess.run([rerun_bin(), "rrd", "print", str(rrd)], capture_output=True, text=True,
                       env={"RERUN_ANALYTICS": "0", "PATH": ""})
    assert p.returncode == 0, p.stderr
    for entity in ("world/ego/camera/left/lanes/boundaries", "world/ego/camera/left/lanes/evidence",
                   "world/ego/lanes/path", "lanes/offset_m/estimate", "lanes/curvature_1pm/truth"):
        assert entity in p.stdout, entity


def test_privileged_puts_every_slot_on_ground_truth_and_a_slot_option_still_wins(tmp_path):
    js = tmp_path / "p.json"
    r = runner.invoke(app, ["drive", "--duration", "0.5", "--privileged", "--lanes", "vision", "--no-record",
                            "--json", str(js)])
    assert r.exit_code == 0, r.output
    assert json.loads(js.read_text())["slots"] == {"lanes": "vision", "longitudinal": "privileged",
                                                   "pedestrians": "privileged", "odometry": "privileged",
                                                   "neighbours": "privileged"}


def test_drive_default_recording_path(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    r = runner.invoke(app, ["drive", "--scenario", "cut-in", "--seed", "2", "--duration", "0.2"])
    assert r.exit_code == 0, r.output
    assert (tmp_path / "runs" / "cut-in-clear-2.rrd").exists()


@pytest.mark.parametrize("args, message", [
    (["--scenario", "motorway"], "unknown scenario 'motorway'"),
    (["--condition", "snow"], "unknown condition 'snow'"),
    (["--pedestrians", "vision", "--detector", "nope.npz"], "--detector must be sim, inria or a model file"),
    (["--duration", "-3"], "--duration must be a finite number"),
    (["--duration", "inf"], "--duration must be a finite number"),
    (["--duration", "1e308"], "--duration must be a finite number"),
    (["--seed", "-1"], "--seed must be a finite number between 0 and"),
])
def test_drive_bad_input_is_one_line_exit_2(tmp_path, args, message, one_line_error):
    js, rrd = tmp_path / "r.json", tmp_path / "r.rrd"
    one_line_error(runner.invoke(app, ["drive", *args, "--json", str(js), "--record", str(rrd)]), message)
    assert not js.exists() and not rrd.exists()


def test_drive_unknown_slot_source_is_refused_before_the_run(tmp_path):
    """typer's own usage error: a framed box under CliRunner, one line through the console script
    (tests/cli/test_usage.py)."""
    js, rrd = tmp_path / "r.json", tmp_path / "r.rrd"
    r = runner.invoke(app, ["drive", "--lanes", "magic", "--json", str(js), "--record", str(rrd)])
    assert r.exit_code == 2
    assert "Invalid value for '--lanes'" in r.output and "Traceback" not in r.output
    assert not js.exists() and not rrd.exists()


def test_drive_unwritable_output(tmp_path, one_line_error):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    r = runner.invoke(app, ["drive", "--duration", "0.2", "--no-record", "--json", str(blocker / "r.json")])
    one_line_error(r, "cannot write")


def test_drive_checks_where_an_interrupted_recording_would_go(tmp_path, one_line_error):
    """A folder at RUN.partial.rrd once made Ctrl-C end in a traceback and a left-over temporary; now it is
    refused before the run."""
    (tmp_path / "r.partial.rrd").mkdir()
    r = runner.invoke(app, ["drive", "--duration", "0.2", "--record", str(tmp_path / "r.rrd")])
    one_line_error(r, "r.partial.rrd is a folder")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.partial.rrd"]


def test_drive_says_what_ctrl_c_keeps_at_each_stage(tmp_path):
    from percept.cli.drive_cmd import Recording
    from percept.drive import DriveConfig

    rec = Recording(tmp_path / "r.rrd", DriveConfig(), 5.0, 70, 0.75)
    assert rec.kept() == "nothing was written or replaced"  # before the world (and the recorder) exists
    rec.recorder = type("Closed", (), {"closed_as": tmp_path / "r.partial.rrd"})()
    assert rec.kept() == f"the recording so far is kept as {tmp_path / 'r.partial.rrd'}; no JSON was written or " \
                         "replaced"
    rec.recorder.closed_as = tmp_path / "r.rrd"  # Ctrl-C while the JSON is written, after the recording
    assert rec.kept() == f"the finished recording is {tmp_path / 'r.rrd'}; no JSON was written or replaced"


def test_drive_table_prints_no_python_values():
    r = runner.invoke(app, ["drive", "--scenario", "crossing", "--duration", "2", "--no-record"])
    assert r.exit_code == 0, r.output
    for word in ("None", "True", "False", "[T", "[F", "[]", "nan"):
        assert word not in r.output, word


def test_drive_seed_bound_is_written_in_full(one_line_error):
    r = runner.invoke(app, ["drive", "--seed", "99999999999", "--no-record"])
    one_line_error(r, "between 0 and 2147483647, got 99999999999")


def test_drive_shows_the_swerve_that_avoided_a_close_cut_in(tmp_path):
    js = tmp_path / "run.json"
    r = runner.invoke(app, ["drive", "--scenario", "cut-in-close", "--privileged", "--lane-changes", "on",
                            "--duration", "14", "--no-record", "--json", str(js)])
    assert r.exit_code == 0, r.output
    row = next(line for line in r.output.splitlines() if "evasive" in line)
    assert "1 / 0 / 0" in row
    assert json.loads(js.read_text())["evasive"]["manoeuvres"][0]["kind"] == "swerve"
