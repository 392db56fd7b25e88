"""``folder_lock``: a context manager that makes one process the only writer of a folder for as long as it runs
(``eval --out``): the folder's ``.percept-lock`` holds the owner's pid, host and command line and is file-locked
meanwhile.
"""

from __future__ import annotations

import contextlib
import json
import os
import socket
import sys
import time
from pathlib import Path
from typing import Callable, Iterator

from .held_signals import stop_signals_held
from .outputs import _temporary, _write_all

LOCK_NAME = ".percept-lock"  # the owner file of a folder that a command is writing (``folder_lock``)


class FolderBusy(ValueError):
    """The folder cannot be had: another live process is writing it (the message names it), or its lock path is
    taken by something that is not a lock file."""


@contextlib.contextmanager
def folder_lock(folder: Path | str, command: str, warn: Callable[[str], None] = lambda line: None) -> Iterator[Path]:
    """Be the only writer of ``folder`` (created if missing) for the block: ``folder/.percept-lock`` holds the pid,
    host, start time and ``command`` and is file-locked meanwhile. FolderBusy when a live process (or one on another
    host) owns it; one left by a process that no longer runs here is taken over, said through ``warn``. The owner
    file is removed however the block ends."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    lock = folder / LOCK_NAME
    if lock.exists() and not lock.is_file():
        raise FolderBusy(f"{lock} is not a lock file percept wrote (a folder or a special file); move it away or "
                         f"choose another --out")
    me = json.dumps({"pid": os.getpid(), "host": socket.gethostname(), "command": command, "argv": sys.argv,
                     "started": time.strftime("%Y-%m-%d %H:%M:%S")}).encode()
    with stop_signals_held():
        fd = _take_lock(lock, me, warn)
    try:
        yield lock
    finally:
        with stop_signals_held():
            if _same_file(fd, lock):
                lock.unlink(missing_ok=True)
            os.close(fd)


def _take_lock(lock: Path, me: bytes, warn: Callable[[str], None]) -> int:
    """The open, file-locked owner file ``lock`` holding ``me``: made (linked into place once written) or taken over."""
    import fcntl

    for _ in range(50):  # another process may take or drop the lock between the steps below
        fd, tmp = _temporary(lock)
        try:
            _write_all(fd, me)
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            os.link(tmp, lock)
            return fd
        except BaseException as e:
            os.close(fd)
            if not isinstance(e, FileExistsError):
                raise
        finally:
            tmp.unlink(missing_ok=True)
        if (owner := _read_owner(lock)) is None:
            continue
        who = (f"{owner.get('command', '?')} (pid {owner.get('pid', '?')}, started {owner.get('started', '?')} on "
               f"{owner.get('host', '?')})")
        if owner.get("host") != socket.gethostname() or _running(owner.get("pid")):
            raise FolderBusy(f"{lock.parent} is being written by {who}; wait for it or choose another --out")
        with contextlib.suppress(FileNotFoundError):
            fd = os.open(lock, os.O_RDWR)
            try:
                # a live owner holds the file lock: getting it, on the same file and owner, proves the owner gone
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                if _same_file(fd, lock) and _read_owner(lock) == owner:
                    os.ftruncate(fd, 0)
                    os.pwrite(fd, me, 0)
                    warn(f"{lock} was left by {who}, which no longer runs; taking the folder over")
                    return fd
            except BlockingIOError:
                pass
            os.close(fd)
    raise FolderBusy(f"{lock.parent} is being locked and unlocked by other processes; choose another --out")


def _read_owner(lock: Path) -> dict | None:
    """The owner record in ``lock``; None when it is gone. Any other content counts as a stopped process's."""
    try:
        owner = json.loads(lock.read_text(encoding="utf-8"))
    except FileNotFoundError:
        return None
    except (OSError, ValueError):
        owner = None
    return owner if isinstance(owner, dict) else {"pid": "?", "host": socket.gethostname(), "command": "unknown"}


def _running(pid) -> bool:
    """Whether process ``pid`` runs on this host (another user's process counts)."""
    try:
        os.kill(pid, 0)
    except (ProcessLookupError, OverflowError, TypeError):
        return False
    except PermissionError:
        pass
    return isinstance(pid, int) and pid > 0


def _same_file(fd: int, path: Path) -> bool:
    """Whether ``path`` is still the file open as ``fd``."""
    with contextlib.suppress(OSError):
        return os.path.samestat(os.stat(path), os.fstat(fd))
    return False
