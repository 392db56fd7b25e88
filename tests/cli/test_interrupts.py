"""Ctrl-C and library chatter, through the console script: ``python -m percept`` in a subprocess, SIGINT once some
output exists; the command stops (before its work is done, and long before ``STOP_S``, which only keeps a hung
command from hanging the suite: how fast it stops is no test's business on a loaded machine) with exit code 130 and
one line saying what was kept, and what was there before is byte-identical."""

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

pytestmark = pytest.mark.slow  # every test starts `python -m percept` in a subprocess
runner = CliRunner()
STOP_S = 30.0
"""How long a signalled command may take to exit before the test fails as hung [s]."""
VIDEO = Path(__file__).resolve().parents[2] / ".." / "shared" / "data" / "udacity-lanelines-p1" / "test_videos" \
    / "solidWhiteRight.mp4"


def interrupt(args: list[str], ready, cwd: Path, timeout_s: float = 90.0, sig=signal.SIGINT,
              children: list | None = None) -> tuple[int, str]:
    """Start ``python -m percept ARGS``, wait until ``ready()``, send ``sig``; (exit code, stderr) once it exits
    (within ``STOP_S``).
    ``children``: filled with the pids of the command's child processes at that moment."""
    p = subprocess.Popen([sys.executable, "-m", "percept", *args], cwd=cwd, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
    try:
        t0 = time.monotonic()
        while not ready():
            assert p.poll() is None, p.communicate()
            assert time.monotonic() - t0 < timeout_s, "the command never got going"
            time.sleep(0.02)
        if children is not None:
            children += child_pids(p.pid)
        p.send_signal(sig)
        _, err = p.communicate(timeout=STOP_S)
        return p.returncode, err
    finally:
        if p.poll() is None:
            p.kill()


def child_pids(pid: int) -> list[int]:
    """The processes whose parent is ``pid`` (Linux /proc)."""
    kids = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid:
            kids.append(int(stat.parent.name))
    return kids


def running(pid: int) -> bool:
    """Whether ``pid`` still runs (a zombie waiting for its parent to collect it does not)."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


def held_for(condition, seconds: float):
    """A ``ready`` that turns true once ``condition()`` has been true for ``seconds``."""
    since = []

    def ready() -> bool:
        if not since and condition():
            since.append(time.monotonic())
        return bool(since) and time.monotonic() - since[0] >= seconds

    return ready


def interrupted_line(err: str) -> str:
    assert "Traceback" not in err, err
    lines = [ln for ln in err.splitlines() if ln.startswith("interrupted:")]
    assert len(lines) == 1, err
    return lines[0]


def test_ctrl_c_stops_eval_workers_fast_and_the_same_command_resumes(tmp_path, snapshot, temporaries):
    out = tmp_path / "ev"
    args = ["eval", "--scenario", "lead-brake", "--seeds", "0-3", "--duration", "1", "--out", str(out)]
    runs = out / "runs"
    code, err = interrupt([*args, "--workers", "2"], lambda: runs.is_dir() and any(runs.glob("*.json")),
                                  tmp_path)
    assert code == 130, (code, err)
    line = interrupted_line(err)
    kept = snapshot(runs)
    runs_kept = f"{len(kept)} finished run{'' if len(kept) == 1 else 's'}"
    assert line == f"interrupted: {runs_kept} kept in {runs}; run the same command to resume"
    assert not (out / "summary.json").exists() and temporaries(out) == []
    # the same command (one worker here) resumes: the kept runs are reused as they are
    r = runner.invoke(app, args)
    assert r.exit_code == 0, r.output
    assert {k: v for k, v in snapshot(runs).items() if k in kept} == kept and len(snapshot(runs)) == 4


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs /proc (Linux)")
def test_sigterm_stops_eval_and_its_workers_like_ctrl_c(tmp_path, temporaries):
    """`kill`, `timeout` and CI cancels send SIGTERM; it once ended the command at once and left its workers
    running. Now it stops like Ctrl-C: workers ended, finished runs kept, exit code 143."""
    out = tmp_path / "ev"
    kids: list[int] = []
    runs = out / "runs"
    code, err = interrupt(["eval", "--scenario", "lead-brake", "--seeds", "0-5", "--duration", "2",
                                   "--workers", "2", "--out", str(out)],
                                  lambda: runs.is_dir() and any(runs.glob("*.json")), tmp_path, sig=signal.SIGTERM,
                                  children=kids)
    assert code == 143, (code, err)
    assert "finished run" in interrupted_line(err) and temporaries(out) == []
    deadline = time.monotonic() + STOP_S  # multiprocessing's resource tracker leaves when it sees its parent gone
    while [k for k in kids if running(k)] and time.monotonic() < deadline:
        time.sleep(0.05)
    assert len(kids) >= 2 and not [k for k in kids if running(k)], [Path(f"/proc/{k}/cmdline").read_bytes()
                                                                   for k in kids if running(k)]


def test_ctrl_c_during_drive_keeps_the_finished_recording_and_json(tmp_path, snapshot, temporaries):
    out = tmp_path / "d"
    args = ["drive", "--record", str(out / "run.rrd"), "--json", str(out / "run.json")]
    r = runner.invoke(app, [*args, "--duration", "0.2"])
    assert r.exit_code == 0, r.output
    before = snapshot(out)
    # the recorder's temporary exists from its start; a second later the run is under way
    code, err = interrupt([*args, "--duration", "60"], held_for((out / ".run.rrd.part").exists, 1.0),
                                  tmp_path)
    assert code == 130, (code, err)
    assert interrupted_line(err) == (f"interrupted: the recording so far is kept as {out / 'run.partial.rrd'}; "
                                     "no JSON was written or replaced")
    after = snapshot(out)
    assert {k: v for k, v in after.items() if k in before} == before
    assert sorted(map(str, after)) == ["run.json", "run.partial.rrd", "run.rrd"] and temporaries(out) == []


def test_ctrl_c_during_render_keeps_complete_frames(tmp_path, temporaries):
    out = tmp_path / "r"
    code, err = interrupt(["render", "--frames", "500", "--out", str(out)],
                                  lambda: (out / "000001_gt.json").exists(), tmp_path)
    assert code == 130, (code, err)
    n = sum(1 for _ in out.glob("*_gt.json"))
    assert 0 < n < 500
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
    code, err = interrupt(["lanes", str(VIDEO), "--out", str(out), "--json", str(js)],
                                  lambda: temporaries(out) != [], tmp_path)
    assert code == 130, (code, err)
    assert "nothing was written" in interrupted_line(err)
    assert snapshot(out) == before


def test_library_chatter_stays_off_the_terminal(tmp_path, one_line_error):
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
        assert "libpng" not in p.stderr and "JPEG" not in p.stderr, p.stderr
        if code == 2:
            one_line_error(p, name)
        else:
            assert p.returncode == 0 and "Traceback" not in p.stderr, p.stderr
            assert not [ln for ln in p.stderr.splitlines() if ln.startswith("error:")], p.stderr
