"""Closing a recording: a finished run gets its footer; an interrupted, failing or blocked one keeps what it recorded
as RUN.partial.rrd and never replaces a finished RUN.rrd."""

import os
import shutil
import subprocess

import numpy as np
import pytest

from percept.drive import TASKS, DriveConfig, run_drive
from percept.review import RunRecorder, partial_path
from percept.review import recorder as recorder_module
from percept.sensors import StereoRig
from percept.sims import WorldConfig

from .test_recorder import columns_by_entity, verify


def test_an_interrupted_recording_is_kept_beside_a_finished_one(tmp_path):
    final = tmp_path / "X.rrd"
    final.write_bytes(b"a finished recording")
    (tmp_path / ".X.rrd.part").write_bytes(b"left over from a killed run")
    rec = RunRecorder(final, StereoRig(), [np.array([[0.0, 0.0], [100.0, 0.0]])], TASKS)
    assert rec.close(complete=False) == partial_path(final) == tmp_path / "X.partial.rrd"
    assert final.read_bytes() == b"a finished recording"
    verify(tmp_path / "X.partial.rrd", footer=False)
    assert sorted(os.listdir(tmp_path)) == ["X.partial.rrd", "X.rrd"]
    assert rec.close() == tmp_path / "X.partial.rrd"  # closing twice changes nothing


def test_a_run_interrupted_midway_keeps_what_was_recorded(tmp_path):
    final = tmp_path / "W.rrd"
    holder = {}

    class Interrupted(RunRecorder):
        def log_step(self, frame, truth, step):
            if frame.index == 5:
                raise KeyboardInterrupt
            super().log_step(frame, truth, step)

    def factory(world):
        holder["r"] = Interrupted(final, world.cfg.rig, [], TASKS)
        return holder["r"]

    with pytest.raises(KeyboardInterrupt):
        run_drive(DriveConfig(WorldConfig("highway", 0), 1.0, default="privileged"), recorder_factory=factory,
                  render=True)
    kept = holder["r"].close(complete=False)
    verify(kept, footer=False)
    # the rows held as columns (trail, scalars) are sent when the recorder closes
    cols = columns_by_entity(kept)
    assert cols["/world/trajectory"]["Points3D:positions"] == 5
    assert cols["/control/speed_mps/truth"]["Scalars:scalars"] == 5
    assert sorted(os.listdir(tmp_path)) == ["W.partial.rrd"]


def test_a_recording_that_raises_is_closed_as_partial(tmp_path):
    final = tmp_path / "Y.rrd"
    with pytest.raises(RuntimeError):
        with RunRecorder(final, StereoRig(), [], TASKS):
            raise RuntimeError("the run failed")
    assert sorted(os.listdir(tmp_path)) == ["Y.partial.rrd"]


def test_ctrl_c_while_flushing_never_replaces_a_finished_recording(tmp_path):
    """Ctrl-C during the last flush keeps the unfinished file as RUN.partial.rrd."""
    final = tmp_path / "Z.rrd"
    final.write_bytes(b"a finished recording")
    rec = RunRecorder(final, StereoRig(), [], TASKS)
    real_flush = rec.rec.flush

    def interrupted(**kw):
        real_flush(**kw)
        raise KeyboardInterrupt

    rec.rec.flush = interrupted
    with pytest.raises(KeyboardInterrupt):
        rec.close()
    assert final.read_bytes() == b"a finished recording"
    assert sorted(os.listdir(tmp_path)) == ["Z.partial.rrd", "Z.rrd"] and rec.closed_as == tmp_path / "Z.partial.rrd"


def test_ctrl_c_while_finishing_keeps_the_stream_as_partial_and_the_finished_recording(tmp_path, monkeypatch):
    """Ctrl-C as the footer is written (the child process has written its output, not yet renamed): the stream is
    RUN.partial.rrd, the finished RUN.rrd is untouched, no temporary is left."""
    final = tmp_path / "F.rrd"
    final.write_bytes(b"a finished recording")
    real_run = subprocess.run

    def interrupted(*args, **kwargs):
        real_run(*args, **kwargs)
        raise KeyboardInterrupt

    monkeypatch.setattr(recorder_module.subprocess, "run", interrupted)
    rec = RunRecorder(final, StereoRig(), [], TASKS)
    with pytest.raises(KeyboardInterrupt):
        rec.close()
    monkeypatch.undo()
    assert final.read_bytes() == b"a finished recording"
    assert sorted(os.listdir(tmp_path)) == ["F.partial.rrd", "F.rrd"] and rec.closed_as == tmp_path / "F.partial.rrd"
    verify(tmp_path / "F.partial.rrd", footer=False)


def test_a_finishing_step_that_fails_is_an_os_error_and_keeps_the_stream_as_partial(tmp_path, monkeypatch):
    final = tmp_path / "G.rrd"
    final.write_bytes(b"a finished recording")
    rec = RunRecorder(final, StereoRig(), [], TASKS)
    with monkeypatch.context() as m:
        m.setattr(recorder_module, "rerun_cli", lambda: shutil.which("false"))
        with pytest.raises(OSError, match="could not finish the recording"):
            rec.close()
    assert final.read_bytes() == b"a finished recording"
    assert sorted(os.listdir(tmp_path)) == ["G.partial.rrd", "G.rrd"]
    verify(tmp_path / "G.partial.rrd", footer=False)


def test_a_folder_in_the_way_of_the_finished_recording_keeps_the_stream_as_partial(tmp_path):
    (tmp_path / "U.rrd").mkdir()
    rec = RunRecorder(tmp_path / "U.rrd", StereoRig(), [], TASKS)
    with pytest.raises(OSError):
        rec.close()
    assert sorted(os.listdir(tmp_path)) == ["U.partial.rrd", "U.rrd"] and (tmp_path / "U.rrd").is_dir()


def test_a_folder_in_the_way_leaves_no_temporary(tmp_path):
    (tmp_path / "V.partial.rrd").mkdir()
    rec = RunRecorder(tmp_path / "V.rrd", StereoRig(), [], TASKS)
    with pytest.raises(OSError):
        rec.close(complete=False)
    assert sorted(os.listdir(tmp_path)) == ["V.partial.rrd"]
