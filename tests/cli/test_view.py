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


def test_a_web_viewer_that_fails_points_at_the_bind_address_not_at_web(rrd, monkeypatch, one_line_error):
    monkeypatch.setattr(view_cmd, "recording_problem", lambda exe, path: None)
    monkeypatch.setattr(subprocess, "run", lambda cmd, env: subprocess.CompletedProcess(cmd, 1))
    result = runner.invoke(app, ["view", str(rrd), "--web", "--bind", "8.8.8.8"])
    one_line_error(result, "--bind 8.8.8.8 must be an address of this machine")
    assert "try `percept view --web" not in result.output


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


def test_the_web_viewer_says_where_to_open_it(rrd):
    """The recorder's quiet log filter is not handed to the viewer, whose web server names its address at INFO."""
    import os
    import signal
    import sys
    import threading
    import time

    script = "from percept.cli import app; app()"
    p = subprocess.Popen([sys.executable, "-c", script, "view", "--web", str(rrd)], stdout=subprocess.PIPE,
                         stderr=subprocess.STDOUT, text=True, start_new_session=True)
    seen: list[str] = []
    threading.Thread(target=lambda: seen.extend(p.stdout), daemon=True).start()
    try:
        end = time.monotonic() + 60
        while time.monotonic() < end and not any("web-viewer at http://127.0.0.1:" in ln for ln in seen):
            time.sleep(0.2)
        assert any("web-viewer at http://127.0.0.1:" in ln for ln in seen), "".join(seen)
    finally:  # the viewer and its servers with it
        os.killpg(p.pid, signal.SIGTERM)
        p.wait(timeout=30)


def test_a_log_filter_the_user_set_reaches_the_viewer(monkeypatch):
    from percept.review import QUIET_RUST_LOG

    monkeypatch.setenv("RUST_LOG", QUIET_RUST_LOG)
    assert "RUST_LOG" not in view_cmd.rerun_env()
    monkeypatch.setenv("RUST_LOG", "debug")
    assert view_cmd.rerun_env()["RUST_LOG"] == "debug"
