"""Atomic outputs: a result file is complete or absent, never half-written.

Every writer here writes to a temporary file in the target's own folder (so that the final rename is on the same
file system), flushes and fsyncs it, then renames it over the target with ``os.replace`` (atomic on POSIX and
Windows). On any failure -- a full disk, an error, Ctrl-C (KeyboardInterrupt) -- the temporary is removed and the
exception propagates; whatever the target held before is left untouched.

- ``write_bytes_atomic``, ``write_text_atomic``, ``write_json_atomic``: one file from bytes, text or a JSON value.
- ``write_files_atomic``: several files as one unit (e.g. a rendered frame's images, depth and ground truth): all
  are written to temporaries first, then renamed; a failure part-way removes the ones already renamed.
- ``atomic_path``: a context manager yielding a temporary path (same suffix as the target, so libraries that pick
  a format by extension work) for writers that need a file name (``cv2.VideoWriter``); renamed into place only
  when the block completes without an exception.

A target that is a symbolic link is written through it (the link stays, its file is replaced); one that is no
regular file (a FIFO, a device such as /dev/null) is written to directly, as no rename can replace it.

A leaf module: it imports nothing from percept, so every package may use it. ``percept.folder_lock`` makes one
process the only writer of a folder.
"""

from __future__ import annotations

import contextlib
import json
import os
import stat
import tempfile
from pathlib import Path
from typing import Any, Iterator, Mapping

from .held_signals import stop_signals_held

_CHUNK = 1 << 20
_os_write = os.write
"""The one call that puts bytes on disk (tests replace it to simulate a full disk)."""


def _mode() -> int:
    """Permissions of a new file under the current umask (mkstemp's own 0600 would hide results from others)."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def _temporary(path: Path) -> tuple[int, Path]:
    """An open, empty temporary file beside ``path``: ``.NAME.<random>.tmp<SUFFIX>`` (hidden, same suffix)."""
    fd, name = tempfile.mkstemp(dir=path.parent, prefix=f".{path.stem}.", suffix=f".tmp{path.suffix}")
    try:
        os.fchmod(fd, _mode())
    except (AttributeError, OSError):  # pragma: no cover - Windows, or a file system without modes
        pass
    return fd, Path(name)


def _destination(path: Path | str) -> Path:
    """Where a write to ``path`` lands: the file a symbolic link points to (so that the link stays a link), else
    ``path``."""
    path = Path(path)
    return Path(os.path.realpath(path)) if path.is_symlink() else path


def _special(path: Path) -> bool:
    """Whether ``path`` exists and is neither a regular file nor a folder (a FIFO, a device, a socket)."""
    try:
        mode = os.stat(path).st_mode
    except OSError:
        return False
    return not stat.S_ISREG(mode) and not stat.S_ISDIR(mode)


def _write_all(fd: int, data: bytes | bytearray | memoryview) -> None:
    view = memoryview(data).cast("B")
    while view:
        n = _os_write(fd, view[:_CHUNK])
        view = view[n:]


def _sync_dir(folder: Path) -> None:
    """Make a rename durable: fsync the folder that holds the new name (best effort; not on every platform)."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def _stage(path: Path, data: bytes) -> Path:
    """Write ``data`` to a fsynced temporary beside ``path``; the temporary's path (removed on any failure)."""
    tmp = None
    try:
        fd, tmp = _temporary(path)
        try:
            _write_all(fd, data)
            os.fsync(fd)
        finally:
            os.close(fd)
        return tmp
    except BaseException:
        if tmp is not None:
            tmp.unlink(missing_ok=True)
        raise


def write_bytes_atomic(path: Path | str, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically (temporary, fsync, rename)."""
    write_files_atomic({Path(path): data})


def write_text_atomic(path: Path | str, text: str, encoding: str = "utf-8") -> None:
    """Write ``text`` to ``path`` atomically: ``path`` is never left half-written."""
    write_bytes_atomic(path, text.encode(encoding))


def write_json_atomic(path: Path | str, data: Any, indent: int | None = 2) -> None:
    """Write ``data`` as JSON to ``path`` atomically (the value is serialised before anything touches the disk)."""
    write_text_atomic(path, json.dumps(data, indent=indent))


def write_files_atomic(files: Mapping[Path | str, bytes]) -> None:
    """Write several files as one unit: every file goes to a fsynced temporary first, then all are renamed.

    A failure while writing leaves every target as it was; a failure (or Ctrl-C) while renaming removes the
    targets already renamed, so that a set of new files is complete or absent. Ctrl-C and SIGTERM are held while
    the files are written and take effect when they are in place.
    """
    with stop_signals_held():
        _write_files(files)


def _write_files(files: Mapping[Path | str, bytes]) -> None:
    staged: list[tuple[Path, Path]] = []
    renamed: list[Path] = []
    targets = {_destination(path): data for path, data in files.items()}
    for path in [p for p in targets if _special(p)]:  # nothing to stage: written through
        with open(path, "wb") as f:
            f.write(targets.pop(path))
    try:
        for path, data in targets.items():
            staged.append((_stage(path, data), path))
        for tmp, path in staged:
            os.replace(tmp, path)
            renamed.append(path)
    except BaseException:
        for tmp, _ in staged:
            tmp.unlink(missing_ok=True)
        if len(renamed) < len(staged):
            for path in renamed:
                path.unlink(missing_ok=True)
        raise
    for folder in {p.parent for _, p in staged}:
        _sync_dir(folder)


@contextlib.contextmanager
def atomic_path(path: Path | str) -> Iterator[Path]:
    """Yield a temporary path beside ``path`` (same suffix) for a writer that needs a file name; when the block
    completes, the file is fsynced and renamed to ``path``. On an exception (KeyboardInterrupt included) the
    temporary is removed and ``path`` keeps what it held.

    The writer must have closed the file (e.g. ``VideoWriter.release()``) by the end of the block. A writer that
    reports failure by a return value must raise inside the block, or nothing tells this manager to discard.
    """
    path = _destination(path)
    if _special(path):  # no temporary can be renamed over it: the writer writes to it
        yield path
        return
    tmp = None
    try:
        fd, tmp = _temporary(path)
        os.close(fd)
        yield tmp
        fd = os.open(tmp, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
        os.replace(tmp, path)
    except BaseException:
        if tmp is not None:
            tmp.unlink(missing_ok=True)
        raise
    _sync_dir(path.parent)


def png_bytes(image) -> bytes:
    """An image (H, W[, C]) uint8 encoded as PNG in memory, for the atomic writers; OSError when OpenCV cannot."""
    import cv2

    ok, buf = cv2.imencode(".png", image)
    if not ok:
        raise OSError(f"cannot encode a {getattr(image, 'shape', '?')} image as PNG")
    return buf.tobytes()


def npy_bytes(array) -> bytes:
    """An array in NumPy's .npy format, in memory, for the atomic writers."""
    import io

    import numpy as np

    buf = io.BytesIO()
    np.save(buf, array)
    return buf.getvalue()
