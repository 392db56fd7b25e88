"""Outputs you can trust: atomic writers, a full disk, bad numbers and outputs that would destroy inputs.

Full disks are simulated by the atomic writer's one call that puts bytes on disk (``percept.outputs._os_write``)
failing with ENOSPC part-way. Ctrl-C and library chatter: tests/cli/test_interrupts.py.
"""

import errno
import json
import os
import signal
import threading
import time
from pathlib import Path

import cv2
import numpy as np
import pytest
from typer.testing import CliRunner

from percept import outputs
from percept.cli import app
from percept.sensors import PinholeCamera
from percept.sensors.chessboard import CameraCalibration

runner = CliRunner()


@pytest.fixture
def disk_full(monkeypatch):
    """``disk_full(after=N, when=pred)``: the disk takes N more bytes (of files whose target path satisfies
    ``pred``), then every write fails with ENOSPC. Which file a descriptor writes is learnt from the writer's own
    temporaries (``outputs._temporary``)."""

    def arm(after: int = 0, when=lambda path: True):
        left = [after]
        real_write, real_temporary = outputs._os_write, outputs._temporary
        target: dict[int, str] = {}

        def temporary(path):
            fd, name = real_temporary(path)
            target[fd] = str(name)
            return fd, name

        def write(fd, data):
            if not when(target.get(fd, "")):
                return real_write(fd, data)
            if len(data) > left[0]:
                if left[0]:
                    real_write(fd, bytes(data[:left[0]]))
                left[0] = 0
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
            left[0] -= len(data)
            return real_write(fd, data)

        monkeypatch.setattr(outputs, "_temporary", temporary)
        monkeypatch.setattr(outputs, "_os_write", write)

    return arm


# --- the atomic writers ---------------------------------------------------------------------------------------


def test_atomic_writers_replace_whole_files_with_ordinary_permissions(tmp_path, temporaries):
    p = tmp_path / "a.json"
    outputs.write_json_atomic(p, {"x": 1})
    outputs.write_text_atomic(tmp_path / "b.txt", "hello")
    outputs.write_bytes_atomic(tmp_path / "c.bin", b"\x00\x01")
    assert json.loads(p.read_text()) == {"x": 1} and (tmp_path / "b.txt").read_text() == "hello"
    assert (tmp_path / "c.bin").read_bytes() == b"\x00\x01"
    mask = os.umask(0)
    os.umask(mask)
    assert p.stat().st_mode & 0o777 == 0o666 & ~mask
    assert temporaries(tmp_path) == []


@pytest.mark.parametrize("after", [0, 5])
def test_a_full_disk_leaves_the_old_file_and_no_temporary(tmp_path, disk_full, after, snapshot):
    p = tmp_path / "result.json"
    p.write_text('{"good": true}')
    before = snapshot(tmp_path)
    disk_full(after)
    with pytest.raises(OSError) as e:
        outputs.write_json_atomic(p, {"new": "x" * 1000})
    assert e.value.errno == errno.ENOSPC
    assert snapshot(tmp_path) == before


def test_an_interrupt_or_error_inside_atomic_path_discards_the_temporary(tmp_path, temporaries):
    target = tmp_path / "video.mp4"
    target.write_bytes(b"complete old video")
    for exc in (KeyboardInterrupt, ValueError):
        with pytest.raises(exc), outputs.atomic_path(target) as tmp:
            assert tmp.parent == tmp_path and tmp.suffix == ".mp4" and tmp.name.startswith(".")
            tmp.write_bytes(b"half a vid")
            raise exc()
        assert target.read_bytes() == b"complete old video" and temporaries(tmp_path) == []
    with outputs.atomic_path(target) as tmp:
        tmp.write_bytes(b"new")
    assert target.read_bytes() == b"new" and temporaries(tmp_path) == []


def test_a_set_of_files_is_complete_or_absent(tmp_path, disk_full, snapshot):
    files = {tmp_path / "0_left.png": b"L" * 100, tmp_path / "0_right.png": b"R" * 100, tmp_path / "0_gt.json": b"{}"}
    disk_full(after=150)
    with pytest.raises(OSError):
        outputs.write_files_atomic(files)
    assert snapshot(tmp_path) == {}


def test_ctrl_c_while_a_set_is_written_lands_after_it_even_with_other_threads(tmp_path, monkeypatch, temporaries):
    """With another thread alive the kernel may hand a process-wide SIGINT to it; the stop must still wait until
    every file of the set is in place."""
    stop, ready = threading.Event(), threading.Event()
    other = threading.Thread(target=lambda: (ready.set(), stop.wait(10)))
    other.start()
    ready.wait(5)
    staged = []
    real_stage = outputs._stage

    def stage_then_ctrl_c(path, data):
        staged.append(real_stage(path, data))
        if len(staged) == 1:
            signal.pthread_kill(other.ident, signal.SIGINT)  # the signal reaches the other thread, as it can
            time.sleep(0.05)
        return staged[-1]

    monkeypatch.setattr(outputs, "_stage", stage_then_ctrl_c)
    # Ctrl-C as Python's default handler takes it (an earlier command in this process may have left it ignored)
    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with pytest.raises(KeyboardInterrupt):
            outputs.write_files_atomic({tmp_path / "a.bin": b"a", tmp_path / "b.bin": b"b"})
    finally:
        signal.signal(signal.SIGINT, old)
        stop.set()
        other.join()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.bin", "b.bin"] and temporaries(tmp_path) == []


def test_calibration_save_on_a_full_disk_keeps_the_old_file(tmp_path, disk_full, snapshot):
    cal = CameraCalibration(PinholeCamera(1000.0, 1000.0, 640.0, 360.0, 1280, 720), (0.0,) * 5, 0.5)
    path = tmp_path / "calib.json"
    cal.save(path)
    before = snapshot(tmp_path)
    disk_full(after=40)
    with pytest.raises(OSError):
        CameraCalibration(PinholeCamera(900.0, 900.0, 640.0, 360.0, 1280, 720), (0.0,) * 5, 0.4).save(path)
    assert snapshot(tmp_path) == before and CameraCalibration.load(path) == cal


# --- commands on a full disk and on bad input -------------------------------------------------------------


@pytest.fixture
def grey_image(tmp_path):
    path = tmp_path / "in" / "grey.png"
    path.parent.mkdir()
    cv2.imwrite(str(path), np.full((270, 480, 3), 90, np.uint8))
    return path


def test_lanes_json_on_a_full_disk_keeps_the_old_json(tmp_path, grey_image, disk_full, snapshot, one_line_error):
    js = tmp_path / "out" / "lanes.json"
    assert runner.invoke(app, ["lanes", str(grey_image), "--json", str(js)]).exit_code == 0
    before = snapshot(tmp_path / "out")
    disk_full(after=64)
    one_line_error(runner.invoke(app, ["lanes", str(grey_image), "--json", str(js)]), "No space left on device")
    assert snapshot(tmp_path / "out") == before


def test_lanes_overlay_on_a_full_disk_keeps_the_old_overlay(tmp_path, grey_image, disk_full, snapshot, one_line_error):
    out = tmp_path / "ov"
    assert runner.invoke(app, ["lanes", str(grey_image), "--out", str(out)]).exit_code == 0
    before = snapshot(out)
    assert list(before) == [Path("grey.lanes.png")]
    disk_full(after=1000)
    one_line_error(runner.invoke(app, ["lanes", str(grey_image), "--out", str(out)]), "cannot write")
    assert snapshot(out) == before


def test_lanes_bad_input_does_not_replace_a_good_json(tmp_path, grey_image, one_line_error):
    js = tmp_path / "lanes.json"
    assert runner.invoke(app, ["lanes", str(grey_image), "--json", str(js)]).exit_code == 0
    good = js.read_bytes()
    (tmp_path / "broken.jpg").write_text("not a jpeg")
    one_line_error(runner.invoke(app, ["lanes", str(tmp_path / "broken.jpg"), "--json", str(js)]), "cannot read")
    empty = tmp_path / "junk"
    empty.mkdir()
    (empty / "a.png").write_text("junk")
    one_line_error(runner.invoke(app, ["lanes", str(empty), "--json", str(js)]), "could be read")
    assert js.read_bytes() == good


@pytest.mark.parametrize("args, message", [
    (["--hfov", "inf"], "--hfov must be a finite number between 3 and 177"),
    (["--speed", "nan"], "--speed must be a finite number"),
    (["--mount-height", "-1"], "--mount-height must be a finite number between 0.2 and 10"),
    (["--max-frames", "0"], "--max-frames must be a finite number"),
])
def test_lanes_bad_numbers_are_one_line(grey_image, args, message, one_line_error):
    one_line_error(runner.invoke(app, ["lanes", str(grey_image), *args]), message)


def test_outputs_are_checked_before_the_work(tmp_path, grey_image, one_line_error):
    blocker = tmp_path / "afile"
    blocker.write_text("x")
    one_line_error(runner.invoke(app, ["lanes", str(grey_image), "--json", str(grey_image)]), "also an input")
    one_line_error(runner.invoke(app, ["lanes", str(grey_image), "--json", str(blocker / "r.json")]),
                   "is a file, not a folder")
    one_line_error(runner.invoke(app, ["lanes", str(grey_image), "--out", str(blocker)]), "is a file; give a folder")
    one_line_error(runner.invoke(app, ["lanes", str(grey_image), "--out", str(blocker / "sub")]),
                   "is a file, not a folder")
    assert blocker.read_text() == "x" and grey_image.stat().st_size > 0


def test_a_parent_that_is_a_file_is_named_as_given(tmp_path, grey_image, monkeypatch, one_line_error):
    monkeypatch.chdir(tmp_path)
    Path("afile").write_text("x")
    one_line_error(runner.invoke(app, ["lanes", str(grey_image), "--json", "afile/deep/r.json"]),
                   "cannot write afile/deep/r.json: afile is a file, not a folder")


def test_a_failed_command_leaves_its_error_as_the_last_line(tmp_path, one_line_error):
    """The progress bar was printed after the error (its final state); it now disappears when the command fails."""
    jpg = cv2.imencode(".jpg", np.full((120, 160, 3), 90, np.uint8))[1].tobytes()
    (tmp_path / "half.jpg").write_bytes(jpg[: len(jpg) // 2])
    r = runner.invoke(app, ["lanes", str(tmp_path / "half.jpg")])
    one_line_error(r, "truncated")
    assert r.output.splitlines() == [ln for ln in r.output.splitlines() if ln.startswith("error:")], r.output


@pytest.mark.parametrize("args, message", [
    (["--square", "inf"], "--square must be a finite number"),
    (["--square", "0"], "--square must be a finite number"),
    (["--pattern", "2x2"], "at least 3x3"),
])
def test_calibrate_bad_numbers_are_one_line(tmp_path, grey_image, args, message, one_line_error):
    one_line_error(runner.invoke(app, ["calibrate", str(grey_image.parent), *args]), message)


def test_calibrate_refuses_to_overwrite_a_photo(grey_image, one_line_error):
    before = grey_image.read_bytes()
    one_line_error(runner.invoke(app, ["calibrate", str(grey_image.parent), "--out", str(grey_image)]),
                   "also an input")
    one_line_error(runner.invoke(app, ["calibrate", str(grey_image.parent), "--json", str(grey_image)]),
                   "also an input")
    assert grey_image.read_bytes() == before


def test_render_on_a_full_disk_keeps_whole_frames_only(tmp_path, disk_full, temporaries, one_line_error):
    out = tmp_path / "r"
    disk_full(after=5000, when=lambda path: "000002_" in path)
    r = runner.invoke(app, ["render", "--frames", "4", "--out", str(out), "--no-scenery"])
    one_line_error(r, "No space left on device")
    assert "2 complete frames kept" in r.output
    names = sorted(p.name for p in out.iterdir())
    assert names == ["000000_depth.npy", "000000_gt.json", "000000_left.png", "000000_right.png",
                     "000001_depth.npy", "000001_gt.json", "000001_left.png", "000001_right.png", "camera.json"]
    assert temporaries(out) == []


def test_render_refuses_a_used_folder_unless_forced(tmp_path, snapshot, one_line_error):
    out = tmp_path / "r"
    assert runner.invoke(app, ["render", "--frames", "2", "--out", str(out), "--no-scenery"]).exit_code == 0
    before = snapshot(out)
    one_line_error(runner.invoke(app, ["render", "--frames", "1", "--out", str(out)]), "already holds a render")
    assert snapshot(out) == before
    r = runner.invoke(app, ["render", "--frames", "1", "--out", str(out), "--no-scenery", "--force"])
    assert r.exit_code == 0, r.output
    assert sorted(p.name for p in out.iterdir()) == ["000000_depth.npy", "000000_gt.json", "000000_left.png",
                                                    "000000_right.png", "camera.json"]
    (out / "notes.txt").write_text("mine")
    one_line_error(runner.invoke(app, ["render", "--frames", "1", "--out", str(out), "--force"]),
                   "did not write (e.g. notes.txt)")
    assert (out / "notes.txt").read_text() == "mine" and (out / "000000_gt.json").exists()


@pytest.mark.slow
def test_eval_on_a_full_disk_keeps_the_finished_runs(tmp_path, disk_full, snapshot, one_line_error):
    args = ["eval", "--scenario", "lead-brake", "--duration", "1", "--out", str(tmp_path)]
    assert runner.invoke(app, [*args, "--seeds", "0"]).exit_code == 0
    before = snapshot(tmp_path)
    disk_full(after=100)
    one_line_error(runner.invoke(app, [*args, "--seeds", "0-1"]), "No space left on device")
    assert snapshot(tmp_path) == before
