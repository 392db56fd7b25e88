"""`percept view RUN.rrd`: open a recording in the Rerun viewer (the one installed with rerun-sdk).

Registered on the main typer app by ``percept.cli.app``.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import typer


def rerun_executable() -> str | None:
    """The ``rerun`` viewer beside this Python (the rerun-sdk wheel installs it there), else on PATH."""
    exe = Path(sys.executable).with_name("rerun")
    return str(exe) if exe.exists() else shutil.which("rerun")


def register(app: typer.Typer) -> None:
    """Add the ``view`` command to ``app``."""

    @app.command("view")
    def view(
        recording: Path = typer.Argument(..., help="A recording from `percept drive` (RUN.rrd)."),
        web: bool = typer.Option(False, "--web", help="Serve the web viewer instead of opening a window (for a "
                                                      "machine without a display; open the printed address)."),
    ):
        """Open a recording in the Rerun viewer, with the blueprint it was recorded with."""
        from percept.cli.app import fail

        if not recording.is_file():
            fail(f"{recording} does not exist; record one with `percept drive --record {recording}`")
        if recording.suffix != ".rrd":
            fail(f"{recording} is not a Rerun recording (.rrd)")
        exe = rerun_executable()
        if exe is None:
            fail("the Rerun viewer is not installed: pip install rerun-sdk")
        cmd = [exe, *(["--web-viewer"] if web else []), str(recording)]
        try:
            code = subprocess.run(cmd, env={**os.environ, "RERUN_ANALYTICS": os.environ.get("RERUN_ANALYTICS", "0")}
                                  ).returncode
        except OSError as e:
            fail(f"cannot start the Rerun viewer ({e.strerror or e})")
        if code != 0:
            fail(f"the Rerun viewer stopped with exit code {code}; without a display, try `percept view --web "
                 f"{recording}`")
