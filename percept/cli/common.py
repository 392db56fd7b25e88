"""What every command shares: the consoles, the one-line error, the progress bar, output-path checks, JSON out,
and the start-up of the console script (quiet libraries, Ctrl-C as one line and exit code 130)."""

from __future__ import annotations

import contextlib
import errno
import os
import re
import signal
import sys
from pathlib import Path
from typing import Callable, Iterable, Iterator, Optional, Union

import typer
from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, MofNCompleteColumn, Progress, ProgressColumn, TextColumn, TimeRemainingColumn
from rich.text import Text
from typer.core import TyperCommand, TyperGroup

from .chatter import filter_native_stderr, quiet_libraries

console = Console()
err = Console(stderr=True)


def error_line(message: str) -> None:
    """Print ``error: message`` as one line on stderr (line breaks in ``message`` become spaces)."""
    err.print(f"[bold red]error:[/] {escape(message.strip().replace(chr(10), ' '))}", highlight=False,
              soft_wrap=True)


def fail(message: str) -> None:
    """Print ``error: message`` on one line and exit with code 2."""
    error_line(message)
    raise typer.Exit(2)


class _Bar(Progress):
    """A progress bar that disappears when its command fails, so that the error stays the last line (after
    Ctrl-C it stays: it shows how far the work got)."""

    def __exit__(self, kind, value, traceback) -> None:
        failed = kind is not None and not issubclass(kind, KeyboardInterrupt) and getattr(value, "exit_code", 1) != 0
        if not failed:
            return super().__exit__(kind, value, traceback)
        self.live.transient = True
        self.live.stop()  # cleared, and no line ending the bar (Progress.stop would print one)


class MeanPaceRemaining(ProgressColumn):
    """Time left at the mean pace since the task started, for steps a minute long (evaluation runs): Rich's own
    column looks at the last 30 s only, where two workers' runs finishing together read as a run every second.
    Steps completed when the task was added (``completed=``, e.g. runs reused by a resumed batch) are not pace."""

    def render(self, task) -> Text:
        done = task.completed - task.fields.get("start_completed", 0)
        if task.total is None or task.elapsed is None or done <= 0:
            return Text("-:--:--", style="progress.remaining")
        left_s = int(task.elapsed / done * max(task.total - task.completed, 0))
        return Text(f"{left_s // 3600}:{left_s // 60 % 60:02d}:{left_s % 60:02d}", style="progress.remaining")


def progress_bar(long_steps: bool = False) -> Progress:
    """The commands' progress bar on stderr; ``long_steps``: the time left from the mean pace (``MeanPaceRemaining``)
    rather than Rich's recent one."""
    remaining = MeanPaceRemaining() if long_steps else TimeRemainingColumn()
    return _Bar(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), remaining, console=err,
                transient=False)


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
            fail(f"output {p} is also an input; writing it would destroy the input: give the output another path")
        seen[r] = Path(p)
        if r.is_dir():
            fail(f"output {p} is a folder; give a file path")
        parent = Path(p).parent  # as the user wrote it, for the message
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


@contextlib.contextmanager
def only_writer(folder: Path, command: str) -> Iterator[None]:
    """Hold ``folder``'s lock (``percept.folder_lock``) for the block: a one-line exit 2 naming the process
    that writes it already, a warning line when a lock left by a stopped process is taken over."""
    from percept.folder_lock import FolderBusy, folder_lock

    def warn(line: str) -> None:
        err.print(f"[yellow]warning:[/] {escape(line)}", highlight=False, soft_wrap=True)

    with contextlib.ExitStack() as stack:
        try:
            stack.enter_context(folder_lock(folder, command, warn))
        except FolderBusy as e:
            fail(str(e))
        except OSError as e:
            fail(f"cannot write into {folder}: {e.strerror or e}; choose a folder you can write to")
        yield


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


class _HelpWithoutType:
    """--help listed without a value type: typer prints ``<bool>`` beside it, as if it took a value."""

    def get_help_option(self, ctx):
        option = super().get_help_option(ctx)
        if option is not None:
            option.metavar = ""
        return option


def reflow(text: str | None) -> str | None:
    """A docstring as help text: the line breaks inside each paragraph joined, since typer's rich help keeps them and
    a paragraph wrapped at 120 columns in the source would print with ragged lines; paragraphs and lines that begin
    a list item ("- ", "* ", "1. ") stay."""
    if not text:
        return text
    out = []
    for para in text.split("\n\n"):
        lines = [line.strip() for line in para.strip().splitlines()]
        joined = []
        for line in lines:
            if joined and not re.match(r"([-*]|\d+\.) ", line):
                joined[-1] += " " + line
            else:
                joined.append(line)
        out.append("\n".join(joined))
    return "\n\n".join(out)


DISK_FULL = (errno.ENOSPC, errno.EDQUOT)
"""The errors of a disk that holds no more: a one-line error wherever a command meets one."""


def disk_full_line(e: OSError) -> str:
    """The one line for a full disk met during a command: what failed, then what the command's interrupt note
    (``on_interrupt``) says is kept."""
    what = e.strerror if e.filename and str(e.filename) in str(e.strerror) else write_error(e.filename, e)
    try:
        note = _interrupt["note"]() if callable(_interrupt["note"]) else _interrupt["note"]
    except Exception:  # noqa: BLE001 - the note must never hide the error itself
        note = None
    return f"{what}; {note}" if note else what


class Command(_HelpWithoutType, TyperCommand):
    """The class of every percept command (``app.command(NAME, cls=Command)``); its help reflowed (``reflow``); a
    full disk met while it runs ends it with one line (``disk_full_line``) and exit code 2."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.help = reflow(self.help)

    def invoke(self, ctx):
        try:
            return super().invoke(ctx)
        except OSError as e:
            if e.errno not in DISK_FULL:
                raise
            fail(disk_full_line(e))


class Group(_HelpWithoutType, TyperGroup):
    """The class of the percept app (``typer.Typer(cls=Group)``)."""


Note = Union[str, Callable[[], str], None]
_interrupt = {"note": None, "signal": None}
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)
"""Ctrl-C, and the polite stop of `kill`, `timeout`, CI cancels and service managers: both stop a command the same
way (workers ended, partial outputs kept, temporaries removed); the exit code is 128 + the signal (130, 143)."""


def on_interrupt(note: Note) -> None:
    """Say what Ctrl-C keeps, for the one line printed when the user interrupts this command: a text, or a
    function called at that moment (e.g. counting the finished runs). None: nothing is kept."""
    _interrupt["note"] = note


def _interrupt_line() -> str:
    """The one line printed after an interrupt: what the command's note says was kept."""
    note = _interrupt["note"]
    try:
        text = note() if callable(note) else note
    except Exception:  # noqa: BLE001 - the note must never hide the interrupt itself
        text = None
    return f"interrupted: {text or 'stopped before finishing; no output was written or replaced'}"


def _on_stop_signal(signum, frame) -> None:
    """SIGINT or SIGTERM: remembered for the exit code, then stops the command as Ctrl-C does."""
    _interrupt["signal"] = signum
    raise KeyboardInterrupt


def _usage_error(e: typer.TyperException) -> int:
    """A command line typer cannot parse (unknown option, bad value, missing argument): one line naming what was
    wrong and where the help is; the error's exit code (2). Without any arguments typer has printed the help."""
    if type(e).__name__ != "NoArgsIsHelpError":
        ctx = getattr(e, "ctx", None)
        error_line(e.format_message() + (f" (see `{ctx.command_path} --help`)" if ctx is not None else ""))
    return getattr(e, "exit_code", 2)


def run_cli(app: Callable[..., None]) -> None:
    """Run the typer ``app`` as the console script: quiet libraries; usage errors as one line; Ctrl-C (SIGINT) or
    SIGTERM stops the command as a KeyboardInterrupt, then ONE line says what was kept (see ``on_interrupt``) and
    the exit code is 130 (143 for SIGTERM)."""
    quiet_libraries()
    restore = filter_native_stderr()
    for sig in STOP_SIGNALS:
        signal.signal(sig, _on_stop_signal)
    code = 0
    try:
        # not standalone: usage errors come back here to be printed as one line; Exit codes are returned
        returned = app(standalone_mode=False)
        code = returned if isinstance(returned, int) else 0
    except typer.TyperException as e:
        code = _usage_error(e)
    except typer.Abort:
        code = 1
    except SystemExit as e:
        code = e.code
    except KeyboardInterrupt:
        code = 130
    finally:
        # the command is over: a signal now must not interrupt the last line or the exit
        for sig in STOP_SIGNALS:
            signal.signal(sig, signal.SIG_IGN)
        if _interrupt["signal"] is not None:
            err.print(escape(_interrupt_line()), style="yellow", highlight=False, soft_wrap=True)
            code = 128 + int(_interrupt["signal"])
        restore()
    if _streams_abandoned():  # nothing else is left to finish: end without the finalisers that would wait for good
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code if isinstance(code, int) else int(code is not None))
    sys.exit(code)


def _streams_abandoned() -> bool:
    """Whether a recording was given up on a full disk (``percept.review.recorder.ABANDONED``); looked up only if
    the recorder was imported, so that commands without one do not load Rerun."""
    recorder = sys.modules.get("percept.review.recorder")
    return recorder is not None and bool(recorder.ABANDONED)
