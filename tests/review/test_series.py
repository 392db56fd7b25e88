"""Rows held and sent as columns make the same recording as logging them frame by frame (checked with the rerun
CLI: `rrd optimize` compacts both, `rrd compare --unordered` compares their data but for log_time)."""

import subprocess
from pathlib import Path

import numpy as np
import pytest
import rerun as rr

from percept.cli.view_cmd import rerun_executable
from percept.review import ColumnBuffer

from .test_recorder import ENV

FRAMES = 40
TIMELINE = "sim_time"


def values(frame: int, nudge: float = 0.0) -> dict:
    """One frame's single rows: a series with gaps (NaN and None clear it), a one-point trail, a transform, a
    clear (with ``strips`` and ``people``, rows of several elements and of none)."""
    x = 0.1 * frame + nudge
    gap = frame % 7 == 3
    return {"speed": float("nan") if frame % 11 == 5 else None if gap else np.sin(x), "x": x,
            "yaw": 0.01 * frame, "clear": gap}


STRIP_RGB = [(120, 220, 120), (255, 220, 0), (60, 140, 255)]


def strips(frame: int) -> list[np.ndarray]:
    """One to three strips of 2 to 12 points (a path alone, or with its two boundaries)."""
    return [np.column_stack([np.arange(2 + (frame + k) % 11), np.full(2 + (frame + k) % 11, k), np.zeros(
        2 + (frame + k) % 11)]) for k in range(1 + frame % 3)]


def people(frame: int) -> np.ndarray:
    """Zero to three points (an empty batch clears the points shown)."""
    return np.arange(3 * (frame % 4), dtype=float).reshape(-1, 3)


def by_frame(path: Path, nudge: float = 0.0) -> None:
    rec = rr.RecordingStream("series-test", recording_id="same")
    rec.save(str(path))
    for f in range(FRAMES):
        v = values(f, nudge)
        rec.set_time(TIMELINE, duration=f / 15)
        if v["speed"] is None or not np.isfinite(v["speed"]):
            rec.log("plot/speed", rr.Clear(recursive=False))
        else:
            rec.log("plot/speed", rr.Scalars(v["speed"]))
        rec.log("world/trail", rr.Points3D([[v["x"], 1.0, 0.1]], colors=[(255, 150, 30)], radii=0.15))
        rec.log("world/ego", rr.Transform3D(translation=[v["x"], 0.0, 0.0],
                                            rotation=rr.RotationAxisAngle(axis=[0, 0, 1], radians=v["yaw"])))
        if v["clear"]:
            rec.log("world/stop", rr.Clear(recursive=False))
        rec.log("world/path", rr.LineStrips3D(strips(f), colors=STRIP_RGB[:len(strips(f))], radii=0.1))
        rec.log("world/people", rr.Points3D(people(f), colors=[(60, 220, 255)], radii=0.3,
                                            labels=[f"#{i}" for i in range(len(people(f)))]))
    rec.flush()
    rec.disconnect()


def by_columns(path: Path, flush_every: int) -> None:
    rec = rr.RecordingStream("series-test", recording_id="same")
    rec.save(str(path))
    buf = ColumnBuffer(TIMELINE)
    held = 0
    for f in range(FRAMES):
        v = values(f)
        buf.set_time(f / 15)
        buf.scalar("plot/speed", v["speed"])
        buf.add("world/trail", rr.Points3D, positions=[[v["x"], 1.0, 0.1]], colors=[(255, 150, 30)], radii=[0.15])
        buf.add("world/ego", rr.Transform3D, translation=[[v["x"], 0.0, 0.0]],
                rotation_axis_angle=[rr.RotationAxisAngle(axis=[0, 0, 1], radians=v["yaw"])])
        if v["clear"]:
            buf.clear("world/stop")
        buf.add("world/path", rr.LineStrips3D, strips=strips(f), colors=STRIP_RGB[:len(strips(f))], radii=[0.1])
        buf.add("world/people", rr.Points3D, positions=people(f), colors=[(60, 220, 255)], radii=[0.3],
                labels=[f"#{i}" for i in range(len(people(f)))])
        held += 6 if v["clear"] else 5
        assert len(buf) == held and buf.held_s() == pytest.approx((f % flush_every) / 15)
        if f % flush_every == flush_every - 1:
            buf.flush(rec)
            held = 0
            assert len(buf) == 0 and buf.held_s() == 0
    buf.flush(rec)
    rec.flush()
    rec.disconnect()


def rrd(*args: str, stdout=subprocess.PIPE) -> int:
    return subprocess.run([rerun_executable(), "rrd", *args], env=ENV, stdout=stdout, stderr=subprocess.PIPE,
                          timeout=120).returncode


def same_data(a: Path, b: Path) -> bool:
    for p in (a, b):
        with open(p.with_suffix(".opt.rrd"), "wb") as out:
            assert rrd("optimize", str(p), stdout=out) == 0
    return rrd("compare", "--unordered", str(a.with_suffix(".opt.rrd")), str(b.with_suffix(".opt.rrd"))) == 0


@pytest.mark.parametrize("flush_every", [1, 15, 100])
def test_rows_sent_as_columns_are_the_rows_logged_frame_by_frame(tmp_path, flush_every):
    by_frame(tmp_path / "frames.rrd")
    by_columns(tmp_path / "columns.rrd", flush_every)
    assert same_data(tmp_path / "frames.rrd", tmp_path / "columns.rrd")


def test_the_comparison_sees_a_changed_value(tmp_path):
    by_frame(tmp_path / "frames.rrd", nudge=1e-9)
    by_columns(tmp_path / "columns.rrd", 15)
    assert not same_data(tmp_path / "frames.rrd", tmp_path / "columns.rrd")
