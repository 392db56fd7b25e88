"""`percept view`: the viewer command it starts, and bad input."""

import subprocess

from typer.testing import CliRunner

from percept.cli import app
from percept.cli.view_cmd import rerun_executable

runner = CliRunner()


def test_view_starts_the_rerun_viewer_on_the_recording(tmp_path, monkeypatch):
    rrd = tmp_path / "run.rrd"
    rrd.write_bytes(b"")
    calls = []

    def fake_run(cmd, env):
        calls.append(cmd)
        return subprocess.CompletedProcess(cmd, 0)

    monkeypatch.setattr(subprocess, "run", fake_run)
    assert runner.invoke(app, ["view", str(rrd)]).exit_code == 0
    assert runner.invoke(app, ["view", str(rrd), "--web"]).exit_code == 0
    assert calls == [[rerun_executable(), str(rrd)], [rerun_executable(), "--web-viewer", str(rrd)]]


def test_view_reports_a_viewer_that_fails(tmp_path, monkeypatch):
    rrd = tmp_path / "run.rrd"
    rrd.write_bytes(b"")
    monkeypatch.setattr(subprocess, "run", lambda cmd, env: subprocess.CompletedProcess(cmd, 1))
    r = runner.invoke(app, ["view", str(rrd)])
    assert r.exit_code == 2 and "try `percept view --web" in r.output


def test_view_bad_input(tmp_path):
    r = runner.invoke(app, ["view", str(tmp_path / "missing.rrd")])
    assert r.exit_code == 2 and "does not exist" in r.output and "Traceback" not in r.output
    (tmp_path / "notes.txt").write_text("x")
    r = runner.invoke(app, ["view", str(tmp_path / "notes.txt")])
    assert r.exit_code == 2 and "is not a Rerun recording" in r.output


def test_the_viewer_is_installed():
    assert rerun_executable() is not None
