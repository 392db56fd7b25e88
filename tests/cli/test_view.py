"""`percept view`: the viewer command it starts, the bind address, and recordings that are not valid."""

import subprocess

import pytest
from typer.testing import CliRunner

from percept.cli import app, view_cmd
from percept.cli.view_cmd import recording_problem, rerun_executable

runner = CliRunner()
REAL_RUN = subprocess.run


@pytest.fixture(params=[True, False], ids=["footer", "no-footer"])
def rrd(tmp_path, request):
    """A small valid recording, with an RRD footer and without (as percept's recorder writes them)."""
    import rerun as rr

    path = tmp_path / "run.rrd"
    rec = rr.RecordingStream("percept-test")
    rec.save(str(path), write_footer=request.param)
    rec.set_time("sim_time", duration=0.0)
    rec.log("x", rr.Scalars(1.0))
    rec.flush()
    rec.disconnect()
    return path


@pytest.fixture
def viewer_calls(monkeypatch):
    """Viewer launches are recorded (and succeed); `rerun rrd verify` and `rrd print` run for real."""
    calls = []

    def fake_run(cmd, env, **kw):
        if cmd[1] == "rrd":
            return REAL_RUN(cmd, env=env, **kw)
        calls.append(cmd)
        return subprocess.CompletedProcess(cmd, 0)

    monkeypatch.setattr(subprocess, "run", fake_run)
    return calls


def test_view_starts_the_rerun_viewer_on_the_recording(rrd, viewer_calls):
    assert runner.invoke(app, ["view", str(rrd)]).exit_code == 0
    assert runner.invoke(app, ["view", str(rrd), "--web"]).exit_code == 0
    assert runner.invoke(app, ["view", str(rrd), "--web", "--bind", "0.0.0.0"]).exit_code == 0
    exe = rerun_executable()
    assert viewer_calls == [[exe, "--bind", "127.0.0.1", str(rrd)],
                            [exe, "--bind", "127.0.0.1", "--web-viewer", str(rrd)],
                            [exe, "--bind", "0.0.0.0", "--web-viewer", str(rrd)]]


def test_view_reports_a_viewer_that_fails(rrd, monkeypatch, one_line_error):
    monkeypatch.setattr(view_cmd, "recording_problem", lambda exe, path: None)
    monkeypatch.setattr(subprocess, "run", lambda cmd, env: subprocess.CompletedProcess(cmd, 1))
    one_line_error(runner.invoke(app, ["view", str(rrd)]), "try `percept view --web")


def test_view_bad_input(tmp_path, rrd, one_line_error):
    one_line_error(runner.invoke(app, ["view", str(tmp_path / "missing.rrd")]), "does not exist")
    (tmp_path / "notes.txt").write_text("x")
    one_line_error(runner.invoke(app, ["view", str(tmp_path / "notes.txt")]), "is not a Rerun recording")
    one_line_error(runner.invoke(app, ["view", str(rrd), "--web", "--bind", "localhost:80"]),
                   "--bind must be an IP address")


@pytest.mark.parametrize("content", [b"", b"not a recording", "truncated"])
def test_view_refuses_an_invalid_recording(tmp_path, rrd, viewer_calls, content, one_line_error):
    bad = tmp_path / "bad.rrd"
    bad.write_bytes(rrd.read_bytes()[:200] if content == "truncated" else content)
    for args in (["view", str(bad)], ["view", str(bad), "--web"]):
        r = runner.invoke(app, args)
        one_line_error(r, "is not a valid Rerun recording")
        assert "display" not in r.output and len(r.output.strip().splitlines()) == 1
    assert viewer_calls == []  # never started, never served


def test_recording_problem_accepts_a_valid_recording(rrd):
    assert recording_problem(rerun_executable(), rrd) is None


def test_the_viewer_is_installed():
    assert rerun_executable() is not None


def test_view_says_a_folder_is_a_folder(tmp_path, one_line_error):
    r = runner.invoke(app, ["view", str(tmp_path)])
    one_line_error(r, "is a folder; give a recording file")
    assert "does not exist" not in r.output


def test_a_recording_cut_after_its_header_is_called_truncated(tmp_path, rrd):
    """`rerun rrd verify` accepts such a file with '0 files verified'; that was once the whole explanation."""
    bad = tmp_path / "cut.rrd"
    bad.write_bytes(rrd.read_bytes()[:20])
    problem = recording_problem(rerun_executable(), bad)
    assert problem == "it is truncated or holds no recording"


def test_the_viewer_is_started_as_itself_not_through_a_script():
    """The `rerun` script starts the viewer as a child: stopping the script (Ctrl-C sent to percept alone, a kill)
    left the viewer and its servers running. The viewer binary is run directly."""
    with open(rerun_executable(), "rb") as f:
        assert f.read(2) != b"#!"
