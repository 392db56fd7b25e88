"""What every command shares: the consoles, the one-line error, the progress bar, output-path checks, JSON out,
and the start-up of the console script (quiet libraries, Ctrl-C as one line and exit code 130)."""

from __future__ import annotations

import os
import re
import signal
import sys
import threading
from pathlib import Path
from typing import Callable, Iterable, Optional, Union

import typer
from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

console = Console()
err = Console(stderr=True)


def fail(message: str) -> None:
    """Print ``error: message`` on one line and exit with code 2."""
    err.print(f"[bold red]error:[/] {escape(message)}", highlight=False, soft_wrap=True)
    raise typer.Exit(2)


def progress_bar() -> Progress:
    return Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeRemainingColumn(),
                    console=err, transient=False)


def check_outputs(outputs: Iterable[Optional[Path]], inputs: Iterable[Optional[Path]] = ()) -> None:
    """Before any work: every output file can be written (its folder exists or can be made, it is not a folder),
    no two outputs share a path and none is an input. Exits with a one-line error otherwise."""
    seen: dict[Path, Path] = {}
    ins = {Path(p).resolve() for p in inputs if p is not None}
    for p in outputs:
        if p is None:
            continue
        r = Path(p).resolve()
        if r in seen:
            fail(f"{seen[r]} is given for two outputs; give each its own path")
        if r in ins:
            fail(f"output {p} is also an input; writing it would destroy the input")
        seen[r] = Path(p)
        if r.is_dir():
            fail(f"output {p} is a folder; give a file path")
        parent = r.parent
        while not parent.exists():
            parent = parent.parent
        if not parent.is_dir():
            fail(f"cannot write {p}: {parent} is a file, not a folder; give a path inside a folder")
        try:
            r.parent.mkdir(parents=True, exist_ok=True)
            probe = r.with_name(f".{r.name}.probe")
            probe.write_text("")
            probe.unlink()
        except OSError as e:
            fail(f"cannot write {p}: {e.strerror or e}; give a path in a folder you can write to")


def write_json(path: Optional[Path], data: dict) -> None:
    """Write ``data`` as JSON (temporary file, fsync, rename); a one-line error when the disk refuses, and the file
    keeps what it held."""
    if path is None:
        return
    from percept.outputs import write_json_atomic

    try:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        write_json_atomic(path, data)
    except OSError as e:
        fail(write_error(path, e))


def write_error(path, e: OSError) -> str:
    """The one-line message for an output the disk refused, saying that the old file (if any) is untouched."""
    return f"cannot write {path}: {e.strerror or e}; nothing was replaced (free some space or choose another path)"


def fmt(x, spec: str = "{:.2f}") -> str:
    """A metric for a table: n/a for None, yes/no for booleans, lists item by item."""
    if x is None:
        return "n/a"
    if isinstance(x, bool):
        return "yes" if x else "no"
    if isinstance(x, list):
        return " ".join(fmt(v, spec) for v in x) if x else "none"
    return spec.format(x)


Note = Union[str, Callable[[], str], None]
_interrupt = {"note": None, "hit": False}


def on_interrupt(note: Note) -> None:
    """Say what Ctrl-C keeps, for the one line printed when the user interrupts this command: a text, or a
    function called at that moment (e.g. counting the finished runs). None: nothing is kept."""
    _interrupt["note"] = note


def _interrupt_line() -> str:
    note = _interrupt["note"]
    try:
        text = note() if callable(note) else note
    except Exception:  # noqa: BLE001 - the note must never hide the interrupt itself
        text = None
    return f"interrupted: {text or 'stopped before finishing; no output was written or replaced'}"


def _on_sigint(signum, frame) -> None:
    _interrupt["hit"] = True
    raise KeyboardInterrupt


CHATTER = re.compile(rb"(libpng (warning|error)|Corrupt JPEG data|Premature end of JPEG|Invalid JPEG|Unsupported "
                     rb"marker|Bogus |Warning: unknown JFIF|\[ ?(WARN|ERROR|INFO):\d|\[[\w,. -]+ @ 0x[0-9a-f]+\])")
"""Lines that C libraries write to the process's stderr (libpng, libjpeg, OpenCV's log, FFmpeg) on their own."""


def _pump(source: int, sink: int) -> None:
    with os.fdopen(source, "rb") as lines:
        for line in lines:
            if not CHATTER.match(line.lstrip()):
                os.write(sink, line)


def _filter_native_stderr() -> Callable[[], None]:
    """Route file descriptor 2 (where C libraries and child processes write) through a filter that drops library
    chatter and passes every other line on; Python's own ``sys.stderr`` writes straight to the terminal. Returns
    the function that restores fd 2. PERCEPT_LIBRARY_LOG=1 keeps everything."""
    if os.environ.get("PERCEPT_LIBRARY_LOG"):
        return lambda: None
    try:
        sys.stderr.flush()
        saved = os.dup(2)
        r, w = os.pipe()
        os.dup2(w, 2)
        os.close(w)
    except (OSError, ValueError, AttributeError):
        return lambda: None
    sys.stderr = open(saved, "w", buffering=1, encoding="utf-8", errors="backslashreplace", closefd=False)
    pump = threading.Thread(target=_pump, args=(r, saved), daemon=True, name="stderr-filter")
    pump.start()

    def restore() -> None:
        sys.stderr.flush()
        os.dup2(saved, 2)  # closes the pipe's last writer in this process: the pump reads to the end
        pump.join(timeout=0.2)

    return restore


def quiet_libraries() -> None:
    """Keep library chatter (OpenCV and FFmpeg warnings) off the user's terminal: only our one-line errors reach
    it. Environment variables are inherited by worker processes; set before OpenCV is first used."""
    os.environ.setdefault("OPENCV_LOG_LEVEL", "ERROR")
    os.environ.setdefault("OPENCV_FFMPEG_LOGLEVEL", "-8")  # AV_LOG_QUIET
    if "cv2" in sys.modules:  # already imported: its log level was read, set it directly
        logging = getattr(sys.modules["cv2"], "utils", None) and getattr(sys.modules["cv2"].utils, "logging", None)
        if logging is not None:
            logging.setLogLevel(logging.LOG_LEVEL_ERROR)


def run_cli(app: Callable[[], None]) -> None:
    """Run the typer ``app`` as the console script: quiet libraries; Ctrl-C (SIGINT) stops the command (typer turns
    KeyboardInterrupt into exit code 130), then ONE line says what was kept (see ``on_interrupt``)."""
    quiet_libraries()
    restore = _filter_native_stderr()
    signal.signal(signal.SIGINT, _on_sigint)
    code = 0
    try:
        app()
    except SystemExit as e:
        code = e.code
    except KeyboardInterrupt:
        code = 130
    finally:
        if _interrupt["hit"]:
            signal.signal(signal.SIGINT, signal.SIG_IGN)  # the line and the exit are not interrupted in turn
            err.print(escape(_interrupt_line()), style="yellow", highlight=False, soft_wrap=True)
            code = 130
        restore()
    sys.exit(code)
