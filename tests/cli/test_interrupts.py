"""Ctrl-C and library chatter, through the console script: ``python -m percept`` in a subprocess, SIGINT once some
output exists; the command stops within seconds with exit code 130 and one line saying what was kept, and what
was there before is byte-identical."""

import signal
import subprocess
import sys
import time
from pathlib import Path

import cv2
import numpy as np
import pytest
from typer.testing import CliRunner

from percept.cli import app

runner = CliRunner()
VIDEO = Path(__file__).resolve().parents[2] / ".." / "shared" / "data" / "udacity-lanelines-p1" / "test_videos" \
    / "solidWhiteRight.mp4"


def interrupt(args: list[str], ready, cwd: Path, timeout_s: float = 90.0) -> tuple[int, str, float]:
    """Start ``python -m percept ARGS``, wait until ``ready()``, send SIGINT; (exit code, stderr, seconds to stop)."""
    p = subprocess.Popen([sys.executable, "-m", "percept", *args], cwd=cwd, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
    try:
        t0 = time.monotonic()
        while not ready():
            assert p.poll() is None, p.communicate()
            assert time.monotonic() - t0 < timeout_s, "the command never got going"
            time.sleep(0.02)
        p.send_signal(signal.SIGINT)
        t1 = time.monotonic()
        _, err = p.communicate(timeout=10)
        return p.returncode, err, time.monotonic() - t1
    finally:
        if p.poll() is None:
            p.kill()


def interrupted_line(err: str) -> str:
    assert "Traceback" not in err, err
    lines = [ln for ln in err.splitlines() if ln.startswith("interrupted:")]
    assert len(lines) == 1, err
    return lines[0]


def test_ctrl_c_stops_eval_workers_fast_and_the_same_command_resumes(tmp_path, snapshot, temporaries):
    out = tmp_path / "ev"
    args = ["eval", "--scenario", "lead-brake", "--seeds", "0-3", "--duration", "1", "--out", str(out)]
    runs = out / "runs"
    code, err, stop_s = interrupt([*args, "--workers", "2"], lambda: runs.is_dir() and any(runs.glob("*.json")),
                                  tmp_path)
    assert code == 130 and stop_s < 3.0, (code, stop_s, err)
    line = interrupted_line(err)
    kept = snapshot(runs)
    assert line == f"interrupted: {len(kept)} finished runs kept in {runs}; run the same command to resume"
    assert not (out / "summary.json").exists() and temporaries(out) == []
    # the same command (one worker here) resumes: the kept runs are reused as they are
    r = runner.invoke(app, args)
    assert r.exit_code == 0, r.output
    assert {k: v for k, v in snapshot(runs).items() if k in kept} == kept and len(snapshot(runs)) == 4


def test_ctrl_c_during_render_keeps_complete_frames(tmp_path, temporaries):
    out = tmp_path / "r"
    code, err, stop_s = interrupt(["render", "--frames", "500", "--out", str(out)],
                                  lambda: (out / "000001_gt.json").exists(), tmp_path)
    assert code == 130 and stop_s < 3.0, (code, stop_s, err)
    n = sum(1 for _ in out.glob("*_gt.json"))
    assert interrupted_line(err).startswith(f"interrupted: {n} complete frames kept in {out}")
    names = {p.name for p in out.iterdir()}
    for i in range(n):
        assert {f"{i:06d}_left.png", f"{i:06d}_right.png", f"{i:06d}_depth.npy"} <= names
    assert len(names) == 4 * n + 1 and temporaries(out) == []


@pytest.mark.skipif(not VIDEO.is_file(), reason=f"{VIDEO} is absent (real data in ../shared/data)")
def test_ctrl_c_during_lanes_keeps_the_old_overlay_video_and_json(tmp_path, snapshot, temporaries):
    out = tmp_path / "ov"
    js = out / "v.json"
    r = runner.invoke(app, ["lanes", str(VIDEO), "--out", str(out), "--json", str(js), "--max-frames", "5"])
    assert r.exit_code == 0, r.output
    before = snapshot(out)
    code, err, stop_s = interrupt(["lanes", str(VIDEO), "--out", str(out), "--json", str(js)],
                                  lambda: temporaries(out) != [], tmp_path)
    assert code == 130 and stop_s < 3.0, (code, stop_s, err)
    assert "nothing was written" in interrupted_line(err)
    assert snapshot(out) == before


def test_library_chatter_stays_off_the_terminal(tmp_path):
    """libpng and libjpeg write their own warnings to stderr; the console script lets only its own lines through."""
    rng = np.random.default_rng(0)
    img = rng.integers(0, 255, (240, 320, 3), dtype=np.uint8)
    png = bytearray(cv2.imencode(".png", img)[1].tobytes())
    png[len(png) // 2] ^= 0xFF  # a CRC error inside the image data
    jpg = bytearray(cv2.imencode(".jpg", img)[1].tobytes())
    for i in range(600, 5000, 37):  # damaged entropy-coded data (no new marker), still a complete file
        if 0xFF not in (jpg[i - 1], jpg[i]):
            jpg[i] = 0x41
    (tmp_path / "bad.png").write_bytes(png)
    (tmp_path / "bad.jpg").write_bytes(jpg)
    for name, code in (("bad.png", 2), ("bad.jpg", 0)):
        p = subprocess.run([sys.executable, "-m", "percept", "lanes", str(tmp_path / name)], capture_output=True,
                           text=True, timeout=120)
        assert p.returncode == code, p.stderr
        assert "libpng" not in p.stderr and "JPEG" not in p.stderr and "Traceback" not in p.stderr, p.stderr
        assert len([ln for ln in p.stderr.splitlines() if ln.startswith("error:")]) == (code == 2)
