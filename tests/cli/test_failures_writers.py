"""One writer per output folder, and model files checked before any work: a second `percept eval` into a folder
that a live one is writing is refused at once naming the first, a lock left by a stopped process is taken over,
the lock is gone however the command ends; `drive` and `eval` refuse a garbage, empty or keyless --detector file
in one line before any run, writing nothing."""

import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from percept.cli import app
from percept.folder_lock import LOCK_NAME, FolderBusy, folder_lock

runner = CliRunner()
FAST_EVAL = ["eval", "--scenario", "highway", "--seeds", "0", "--duration", "0.2", "--privileged"]
"""A batch of one short run with every slot privileged (no cameras)."""


def write_lock(folder: Path, pid: int, host: str | None = None) -> Path:
    """An owner file as a `percept eval` of process ``pid`` writes it."""
    folder.mkdir(parents=True, exist_ok=True)
    lock = folder / LOCK_NAME
    lock.write_text(json.dumps({"pid": pid, "host": host or socket.gethostname(), "command": "percept eval",
                                "started": "2026-01-02 03:04:05"}))
    return lock


@pytest.fixture
def live_pid():
    """The pid of a process that runs for the test's length."""
    p = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(120)"])
    yield p.pid
    p.kill()
    p.wait()


@pytest.fixture
def dead_pid():
    """The pid of a process that has ended (and been collected)."""
    p = subprocess.Popen([sys.executable, "-c", "pass"])
    p.wait()
    return p.pid


def test_a_second_eval_into_a_folder_being_written_is_refused_at_once_naming_the_first(tmp_path, live_pid,
                                                                                         one_line_error):
    out = tmp_path / "ev"
    lock = write_lock(out, live_pid)
    before = lock.read_bytes()
    t0 = time.monotonic()
    r = runner.invoke(app, [*FAST_EVAL, "--out", str(out)])
    one_line_error(r, f"{out} is being written by percept eval (pid {live_pid}, started 2026-01-02 03:04:05 on "
                      f"{socket.gethostname()}); wait for it or choose another --out")
    assert time.monotonic() - t0 < 30  # refused before any run (a run of the batch would be driven otherwise)
    assert lock.read_bytes() == before and sorted(p.name for p in out.iterdir()) == [LOCK_NAME]


def test_a_lock_held_on_another_host_is_refused(tmp_path, one_line_error):
    out = tmp_path / "ev"
    write_lock(out, 1, host="some-other-host")
    r = runner.invoke(app, [*FAST_EVAL, "--out", str(out)])
    one_line_error(r, "on some-other-host); wait for it or choose another --out")


@pytest.mark.slow
def test_a_stale_lock_is_taken_over_with_a_warning_and_removed_at_the_end(tmp_path, dead_pid):
    out = tmp_path / "ev"
    write_lock(out, dead_pid)
    r = runner.invoke(app, [*FAST_EVAL, "--out", str(out)])
    assert r.exit_code == 0, r.output
    assert f"warning: {out / LOCK_NAME} was left by percept eval (pid {dead_pid}" in " ".join(r.output.split())
    assert "which no longer runs; taking the folder over" in " ".join(r.output.split())
    assert not (out / LOCK_NAME).exists() and (out / "summary.json").is_file()


@pytest.mark.slow
def test_the_lock_is_gone_after_success_and_after_a_refusal_inside_it(tmp_path, one_line_error):
    out = tmp_path / "ev"
    assert runner.invoke(app, [*FAST_EVAL, "--out", str(out)]).exit_code == 0
    assert not (out / LOCK_NAME).exists()
    # the runs there were made with another duration: refused once the folder is this command's
    r = runner.invoke(app, [*FAST_EVAL[:-3], "--duration", "0.3", "--privileged", "--out", str(out)])
    one_line_error(r, "--redo")
    assert not (out / LOCK_NAME).exists()


def test_the_lock_is_gone_after_a_failure_and_an_exception(tmp_path, monkeypatch, one_line_error):
    import percept.evaluate.batch as batch

    out = tmp_path / "ev"

    def broken(*args, **kwargs):
        raise RuntimeError("the cluster went away")

    monkeypatch.setattr(batch, "evaluate", broken)
    one_line_error(runner.invoke(app, [*FAST_EVAL, "--out", str(out)]), "the cluster went away")
    assert not (out / LOCK_NAME).exists()

    def crash(*args, **kwargs):
        raise ZeroDivisionError("a bug")

    monkeypatch.setattr(batch, "evaluate", crash)
    r = runner.invoke(app, [*FAST_EVAL, "--out", str(out)])
    assert isinstance(r.exception, ZeroDivisionError)
    assert not (out / LOCK_NAME).exists()


@pytest.mark.slow
@pytest.mark.skipif(not hasattr(signal, "SIGINT"), reason="needs signals")
def test_a_real_second_eval_is_refused_while_the_first_runs_and_ctrl_c_removes_the_lock(tmp_path, one_line_error):
    out = tmp_path / "ev"
    first = subprocess.Popen([sys.executable, "-m", "percept", "eval", "--scenario", "lead-brake", "--seeds", "0-99",
                              "--duration", "1", "--out", str(out)], cwd=tmp_path, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
    try:
        t0 = time.monotonic()
        while not (out / LOCK_NAME).exists():
            assert first.poll() is None, first.communicate()
            assert time.monotonic() - t0 < 90, "the first eval never got going"
            time.sleep(0.02)
        second = subprocess.run([sys.executable, "-m", "percept", "eval", "--scenario", "lead-brake", "--seeds", "0-3",
                                 "--duration", "2", "--out", str(out)], cwd=tmp_path, capture_output=True, text=True,
                                timeout=60)
        one_line_error(second, f"{out} is being written by percept eval (pid {first.pid}, started ")
        assert first.poll() is None  # the first goes on
        first.send_signal(signal.SIGINT)
        _, err = first.communicate(timeout=30)
        assert first.returncode == 130, err
        assert not (out / LOCK_NAME).exists()
        assert not [p for p in out.rglob(".*") if ".tmp" in p.name]
    finally:
        if first.poll() is None:
            first.kill()


def test_folder_lock_refuses_a_second_holder_in_the_same_process_and_releases(tmp_path):
    with folder_lock(tmp_path / "d", "percept eval") as lock:
        owner = json.loads(lock.read_text())
        assert owner["pid"] == os.getpid() and owner["command"] == "percept eval"
        with pytest.raises(FolderBusy, match=f"pid {os.getpid()}"):
            with folder_lock(tmp_path / "d", "percept eval"):
                pass
        assert lock.exists()
    assert list((tmp_path / "d").iterdir()) == []


def test_folder_lock_takes_over_an_unreadable_owner_file(tmp_path):
    (tmp_path / LOCK_NAME).write_text("not an owner record")
    said = []
    with folder_lock(tmp_path, "percept eval", said.append):
        assert json.loads((tmp_path / LOCK_NAME).read_text())["pid"] == os.getpid()
    assert len(said) == 1 and "no longer runs" in said[0]
    assert list(tmp_path.iterdir()) == []


def bad_models(folder: Path) -> dict:
    """A garbage, an empty and a keyless .npz in ``folder``: name -> the message's tail."""
    (folder / "garbage.npz").write_bytes(b"this is not a model")
    (folder / "empty.npz").write_bytes(b"")
    np.savez(folder / "keyless.npz", other=np.zeros(3))
    return {"garbage.npz": "(not an .npz archive)", "empty.npz": "(not an .npz archive, it is empty)",
            "keyless.npz": "(it has no weights and no bias array)"}


@pytest.mark.parametrize("command", [["drive", "--duration", "0.2"], ["eval", "--scenario", "highway", "--seeds",
                                                                      "0", "--duration", "0.2", "--out", "ev"]])
def test_a_bad_detector_file_is_refused_in_one_line_before_anything_is_written(tmp_path, monkeypatch, command,
                                                                                one_line_error):
    monkeypatch.chdir(tmp_path)
    for name, why in bad_models(tmp_path).items():
        r = runner.invoke(app, [*command, "--detector", name])
        one_line_error(r, f"--detector: model file {name} is not a percept HOG model {why}")
        assert sorted(p.name for p in tmp_path.iterdir()) == ["empty.npz", "garbage.npz", "keyless.npz"]


def test_a_lock_path_that_is_a_folder_is_named_in_one_line(tmp_path, one_line_error):
    out = tmp_path / "ev"
    (out / LOCK_NAME).mkdir(parents=True)
    r = runner.invoke(app, [*FAST_EVAL, "--out", str(out)])
    one_line_error(r, f"{out / LOCK_NAME} is not a lock file percept wrote")
    assert (out / LOCK_NAME).is_dir() and sorted(p.name for p in out.iterdir()) == [LOCK_NAME]


def test_a_drive_refused_for_a_bad_recording_option_makes_no_folder(tmp_path, monkeypatch, one_line_error):
    monkeypatch.chdir(tmp_path)
    r = runner.invoke(app, ["drive", "--camera-hz", "0", "--duration", "0.2"])
    one_line_error(r, "--camera-hz must be a finite number")
    assert list(tmp_path.iterdir()) == []
