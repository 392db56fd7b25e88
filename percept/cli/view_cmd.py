"""`percept view RUN.rrd`: open a recording in the Rerun viewer (the one installed with rerun-sdk).

Registered on the main typer app by ``percept.cli.app``. The recording is checked first (``rerun rrd verify``), so
that an empty or corrupt file is reported as such rather than as a viewer or display failure. The viewer's servers
listen on 127.0.0.1 unless ``--bind`` says otherwise.
"""

from __future__ import annotations

import importlib.util
import ipaddress
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Annotated

import typer

from .common import Command, fail, on_interrupt
from .options import flag

RRD_MAGIC = b"RRF"
"""Every .rrd file starts with these bytes (then the format version)."""


def rerun_executable() -> str | None:
    """The ``rerun`` viewer: the binary of the ``rerun_cli`` package (installed with rerun-sdk), else the ``rerun``
    script beside this Python or on PATH. The binary itself, not the script that starts it: stopping the script
    (Ctrl-C, a kill) would leave the viewer and its servers running."""
    from percept.review.recorder import rerun_cli

    try:
        return rerun_cli()
    except OSError:
        pass
    exe = Path(sys.executable).with_name("rerun")
    return str(exe) if exe.exists() else shutil.which("rerun")


def rerun_env() -> dict:
    """The environment of a rerun child process: analytics off unless asked for, and the user's own log filter only
    (not the one the recorder sets, which hides the web viewer's line saying where to open it)."""
    from percept.review import QUIET_RUST_LOG

    env = {**os.environ, "RERUN_ANALYTICS": os.environ.get("RERUN_ANALYTICS", "0")}
    if env.get("RUST_LOG") == QUIET_RUST_LOG:
        del env["RUST_LOG"]
    return env


def recording_problem(exe: str, recording: Path) -> str | None:
    """Why ``recording`` is not a valid Rerun recording (one line), or None when ``rerun rrd verify`` accepts it."""
    with open(recording, "rb") as f:
        head = f.read(len(RRD_MAGIC))
    if not head:
        return "the file is empty"
    if head != RRD_MAGIC:
        return "it does not start like a Rerun recording"
    try:
        # an interrupted recording (RUN.partial.rrd, ``review.recorder``) has no footer, nor has any file cut short:
        # not required here
        r = subprocess.run([exe, "rrd", "verify", "--check-footers", "false", str(recording)], env=rerun_env(),
                           capture_output=True, text=True)
    except OSError as e:
        return f"cannot run `rerun rrd verify` ({e.strerror or e})"
    # verify exits 0 on files it cannot read at all ("0 files verified"), so its count is checked too
    if r.returncode == 0 and "1 file verified" in r.stdout + r.stderr:
        # and on a file cut before its first chunk: without a footer the end of the data is where the file ends
        return None if _has_chunks(exe, recording) else "it is truncated or holds no recording"
    lines = [ln.strip() for ln in (r.stdout + r.stderr).splitlines() if ln.strip() and "INFO" not in ln
             and "files verified" not in ln and not ln.startswith("Error: Verification failed")]
    why = next(iter(lines), "it is truncated or holds no recording")
    why = why.removeprefix("Error: ")
    if why.startswith('"'):  # '"FILE": what is wrong'
        why = why.split(": ", 1)[-1]
    return why if len(why) <= 120 else why[:119] + "…"


def _has_chunks(exe: str, recording: Path) -> bool:
    """Whether ``rerun rrd print`` lists at least one chunk of data in ``recording``: read up to the first one, not
    the whole listing (a line per chunk: 0.7 s for a 94 MB recording)."""
    with subprocess.Popen([exe, "rrd", "print", str(recording)], env=rerun_env(), stdout=subprocess.PIPE,
                          stderr=subprocess.DEVNULL, text=True) as p:
        found = any(ln.startswith("Chunk(") for ln in p.stdout)
        p.kill()
    return found


def has_display() -> bool:
    """Whether a window can be opened: on Linux and the BSDs, an X11 or Wayland display is named in the
    environment; elsewhere always."""
    if not sys.platform.startswith(("linux", "freebsd", "openbsd", "netbsd")):
        return True
    return any(os.environ.get(v) for v in ("DISPLAY", "WAYLAND_DISPLAY", "WAYLAND_SOCKET"))


def run_window_viewer(cmd: list[str]) -> tuple[int, str]:
    """Run the native viewer ``cmd`` with its output (start-up logs, a failure's ``Error:`` line) kept from the
    terminal: (exit code, its last ``Error:`` line without the prefix, or "")."""
    with tempfile.TemporaryFile() as log:
        sys.stdout.flush()
        sys.stderr.flush()
        saved = os.dup(1), os.dup(2)
        try:
            os.dup2(log.fileno(), 1)
            os.dup2(log.fileno(), 2)
            code = subprocess.run(cmd, env=rerun_env()).returncode
        finally:
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            os.close(saved[0])
            os.close(saved[1])
        log.seek(0)
        lines = log.read().decode("utf-8", "replace").splitlines()
    why = next((ln.strip().removeprefix("Error: ") for ln in reversed(lines) if ln.startswith("Error: ")), "")
    return code, why


def check_bind(bind: str) -> str:
    """The bind address as given, if it is an IP address (what the rerun CLI's --bind takes)."""
    try:
        ipaddress.ip_address(bind)
    except ValueError:
        fail(f"--bind must be an IP address such as 127.0.0.1 (this machine only) or 0.0.0.0 (every interface), "
             f"got '{bind}'")
    return bind


def register(app: typer.Typer) -> None:
    """Add the ``view`` command to ``app``."""

    @app.command("view", cls=Command)
    def view(
        recording: Path = typer.Argument(..., help="A recording from `percept drive` (RUN.rrd)."),
        web: Annotated[bool, flag("--web", help="Serve the web viewer instead of opening a window (for a machine "
                                                "without a display; open the printed address).")] = False,
        bind: str = typer.Option("127.0.0.1", "--bind", metavar="ADDR",
                                 help="IP address the viewer's servers listen on (0.0.0.0: every interface, to "
                                      "open --web from another machine)."),
    ):
        """Open a recording in the Rerun viewer, with the blueprint it was recorded with."""
        bind = check_bind(bind)
        if recording.is_dir():
            fail(f"{recording} is a folder; give a recording file (RUN.rrd)")
        if not recording.is_file():
            fail(f"{recording} does not exist; record one with `percept drive --record {recording}`")
        if recording.suffix != ".rrd":
            fail(f"{recording} is not a Rerun recording (.rrd)")
        exe = rerun_executable()
        if exe is None:
            fail("the Rerun viewer is not installed: pip install rerun-sdk")
        problem = recording_problem(exe, recording)
        if problem is not None:
            fail(f"{recording} is not a valid Rerun recording ({problem}); record it again with `percept drive`")
        cmd = [exe, "--bind", bind, *(["--web-viewer"] if web else []), str(recording)]
        on_interrupt(f"the viewer was closed; {recording} is unchanged")
        try:
            # the web viewer prints the address to open: its output stays on the terminal
            code, why = (subprocess.run(cmd, env=rerun_env()).returncode, "") if web else run_window_viewer(cmd)
        except OSError as e:
            fail(f"cannot start the Rerun viewer ({e.strerror or e})")
        if code != 0 and not web and not has_display():
            fail(f"no display to open the viewer's window on (DISPLAY and WAYLAND_DISPLAY are not set); try "
                 f"`percept view --web {recording}` and open the address it prints")
        if code != 0 and web:
            fail(f"the Rerun web viewer stopped with exit code {code} (its reason is above); --bind {bind} must be an "
                 f"address of this machine (127.0.0.1, or 0.0.0.0 for every interface) and its ports 9090 and 9876 "
                 f"free")
        if code != 0:
            why = f" ({why if len(why) <= 120 else why[:119] + '…'})" if why else ""
            fail(f"the Rerun viewer stopped with exit code {code}{why}; without a display, try `percept view --web "
                 f"{recording}`")
