"""What every command shares: the consoles, the one-line error, the progress bar, output-path checks, JSON out."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Iterable, Optional

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
            fail(f"cannot write {p}: {parent} is a file, not a folder")
        try:
            r.parent.mkdir(parents=True, exist_ok=True)
            probe = r.with_name(f".{r.name}.probe")
            probe.write_text("")
            probe.unlink()
        except OSError as e:
            fail(f"cannot write {p}: {e.strerror or e}")


def write_json(path: Optional[Path], data: dict) -> None:
    """Write ``data`` as JSON (temporary file, then rename); a one-line error when the disk refuses."""
    if path is None:
        return
    from percept.sensors.chessboard import write_text_atomic

    try:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        write_text_atomic(Path(path), json.dumps(data, indent=2))
    except OSError as e:
        fail(f"cannot write {path}: {e.strerror or e}")


def fmt(x, spec: str = "{:.2f}") -> str:
    """A metric for a table: n/a for None, yes/no for booleans, lists item by item."""
    if x is None:
        return "n/a"
    if isinstance(x, bool):
        return "yes" if x else "no"
    if isinstance(x, list):
        return " ".join(fmt(v, spec) for v in x) if x else "none"
    return spec.format(x)
