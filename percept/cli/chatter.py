"""Library chatter kept off the user's terminal: what C libraries (libpng, libjpeg, OpenCV, FFmpeg) write to the
process's stderr on their own is dropped, so that only percept's own lines reach it."""

from __future__ import annotations

import os
import re
import sys
import threading
from typing import Callable

CHATTER = re.compile(rb"(libpng (warning|error)|Corrupt JPEG data|Premature end of JPEG|Invalid JPEG|Unsupported "
                     rb"marker|Bogus |Warning: unknown JFIF|\[ ?(WARN|ERROR|INFO):\d|\[[\w,. -]+ @ 0x[0-9a-f]+\])")
"""Lines that C libraries write to the process's stderr (libpng, libjpeg, OpenCV's log, FFmpeg) on their own."""


def _pump(source: int, sink: int) -> None:
    """Copy lines from the pipe ``source`` to ``sink`` except library chatter (``CHATTER``)."""
    with os.fdopen(source, "rb") as lines:
        for line in lines:
            if not CHATTER.match(line.lstrip()):
                os.write(sink, line)


def filter_native_stderr() -> Callable[[], None]:
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
