"""A full disk under `percept drive --record` and `percept view` without a display: one line, exit code 2, nothing
left behind, what was there before byte-identical; a drive whose disk fills ends within ``END_S`` of it."""

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest
from typer.testing import CliRunner

from percept.cli import app
from percept.review import RecordOptions
from percept.review import recorder as rec_mod
from percept.review import space as space_mod

runner = CliRunner()
END_S = 10.0
"""How long a drive may run on once its disk is full [s]."""
DRIVE = ["drive", "--scenario", "highway", "--seed", "0"]


def old_outputs(folder: Path) -> dict[Path, bytes]:
    """A finished recording and run JSON already in ``folder``: what must survive byte-identical."""
    old = {folder / "x.rrd": b"RRF2 an older finished recording", folder / "x.json": b'{"old": true}\n'}
    for path, data in old.items():
        path.write_bytes(data)
    return old


def assert_untouched(folder: Path, old: dict[Path, bytes], extra: tuple[str, ...] = ()) -> None:
    """``folder`` holds the old outputs as they were (and the files named in ``extra``), nothing else."""
    assert sorted(p.name for p in folder.iterdir()) == sorted([p.name for p in old] + list(extra))
    for path, data in old.items():
        assert path.read_bytes() == data


def test_a_recording_needs_about_7_mb_a_simulated_minute_at_the_defaults():
    assert 6e6 < space_mod.expected_bytes(60.0, RecordOptions()) < 8e6
    assert 20e6 < space_mod.expected_bytes(60.0, RecordOptions(15.0, 70, 1.0)) < 30e6


def test_the_space_check_names_the_free_space_and_the_need(tmp_path, monkeypatch):
    monkeypatch.setattr(space_mod, "free_bytes", lambda folder: 3_000_000)
    with pytest.raises(OSError) as e:
        space_mod.check_space(tmp_path / "x.rrd", 600.0, RecordOptions())
    assert "3.0 MB free" in str(e.value) and "a 600 s run needs about 156.1 MB" in str(e.value)


@pytest.mark.slow
def test_drive_refuses_a_disk_without_room_in_one_line(tmp_path, monkeypatch, one_line_error):
    old = old_outputs(tmp_path)
    monkeypatch.setattr(space_mod, "free_bytes", lambda folder: 56_000)
    r = runner.invoke(app, [*DRIVE, "--duration", "2", "--record", str(tmp_path / "x.rrd"),
                            "--json", str(tmp_path / "x.json")])
    one_line_error(r, "56 KB free on its disk")
    assert "nothing was written or replaced" in r.output
    assert_untouched(tmp_path, old)


@pytest.mark.slow
def test_a_disk_that_fills_mid_drive_ends_it_in_one_line_leaving_nothing(tmp_path, monkeypatch, one_line_error):
    old = old_outputs(tmp_path)
    part = tmp_path / ".x.rrd.part"
    full_at = []

    def free(folder):
        """Plenty until the part file has been written for a while, then a full disk."""
        if not full_at and part.exists() and part.stat().st_size > 0:
            full_at.append(time.monotonic())
        return 1 << 40 if not full_at else 0

    monkeypatch.setattr(space_mod, "free_bytes", free)
    monkeypatch.setattr(rec_mod, "WATCH_S", 0.5)
    r = runner.invoke(app, [*DRIVE, "--duration", "120", "--record", str(tmp_path / "x.rrd"),
                            "--json", str(tmp_path / "x.json")])
    ended = time.monotonic()
    one_line_error(r, "its disk has filled up (0 KB free); the recording was not kept")
    assert full_at and ended - full_at[0] < END_S
    assert_untouched(tmp_path, old)


@pytest.fixture
def tmpfs(tmp_path):
    """``mount(size)``: a tmpfs of ``size`` (e.g. "64k") at a new folder, unmounted at the end; the test is skipped
    where mounting is not permitted (not root, or in a container without the capability)."""
    mounted = []

    def mount(size: str) -> Path:
        where = tmp_path / f"disk{len(mounted)}"
        where.mkdir()
        r = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(where)], capture_output=True,
                           text=True)
        if r.returncode != 0:
            pytest.skip(f"mounting a tmpfs is not permitted here ({r.stderr.strip() or r.returncode})")
        mounted.append(where)
        return where

    if sys.platform != "linux" or os.geteuid() != 0:
        pytest.skip("mounting a tmpfs needs Linux and root")
    yield mount
    for where in mounted:
        subprocess.run(["umount", "-l", str(where)], check=False)


def percept(args: list[str], cwd: Path) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "percept", *args], cwd=cwd, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env={**os.environ, "SDL_VIDEODRIVER": "dummy"})


@pytest.mark.slow
def test_drive_on_a_full_tmpfs_is_refused_in_one_line(tmpfs, tmp_path, one_line_error):
    disk = tmpfs("64k")
    old = old_outputs(disk)
    p = percept([*DRIVE, "--duration", "20", "--record", str(disk / "x.rrd"), "--json", str(disk / "x.json")],
                tmp_path)
    out, err = p.communicate(timeout=120)
    one_line_error(subprocess.CompletedProcess(p.args, p.returncode, out, err), "free on its disk, a 20 s run needs")
    assert_untouched(disk, old)


@pytest.mark.slow
def test_a_tmpfs_that_fills_mid_drive_ends_it_within_the_limit(tmpfs, tmp_path, one_line_error):
    disk = tmpfs("64m")  # room for the up-front check of a 120 s run, then filled
    old = old_outputs(disk)
    p = percept([*DRIVE, "--duration", "120", "--record", str(disk / "x.rrd"), "--json", str(disk / "x.json")],
                tmp_path)
    try:
        t0 = time.monotonic()
        while not (disk / ".x.rrd.part").exists():
            assert p.poll() is None and time.monotonic() - t0 < 120, p.communicate()
            time.sleep(0.05)
        time.sleep(3.0)  # some of the stream on disk
        with open(disk / "filler", "wb") as f:  # the disk fills up to its last byte
            try:
                while True:
                    f.write(b"\0" * 65536)
                    f.flush()
            except OSError:
                pass
        full_at = time.monotonic()
        out, err = p.communicate(timeout=60)
        ended = time.monotonic()
    finally:
        if p.poll() is None:
            p.kill()
            p.communicate()
    one_line_error(subprocess.CompletedProcess(p.args, p.returncode, out, err), "the recording was not kept")
    assert ended - full_at < END_S
    assert_untouched(disk, old, extra=("filler",))


@pytest.fixture
def rrd(tmp_path):
    """A small valid recording."""
    import rerun as rr

    path = tmp_path / "run.rrd"
    rec = rr.RecordingStream("percept-test")
    rec.save(str(path), write_footer=False)
    rec.set_time("sim_time", duration=0.0)
    rec.log("x", rr.Scalars(1.0))
    rec.flush()
    rec.disconnect()
    return path


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="a display is named in the environment on Linux")
def test_view_without_a_display_is_one_line(rrd, monkeypatch, capfd, one_line_error):
    for name in ("DISPLAY", "WAYLAND_DISPLAY", "WAYLAND_SOCKET"):
        monkeypatch.delenv(name, raising=False)
    r = runner.invoke(app, ["view", str(rrd)])
    one_line_error(r, f"no display to open the viewer's window on (DISPLAY and WAYLAND_DISPLAY are not set); try "
                      f"`percept view --web {rrd}`")
    leaked = capfd.readouterr()
    assert leaked.out.strip() == "" and leaked.err.strip() == ""  # the viewer's own lines stay off the terminal
