"""Ctrl-C and SIGTERM held off a block of code: the atomic writers' guard (``percept.outputs``).

A leaf module: it imports nothing from percept.
"""

from __future__ import annotations

import contextlib
import signal
import threading
from typing import Iterator

__all__ = ["stop_signals_held"]


@contextlib.contextmanager
def stop_signals_held() -> Iterator[None]:
    """Hold Ctrl-C and SIGTERM until the block is done, so that a stop cannot land between creating a temporary and
    noting it down; the stop is delivered right after. The handlers are swapped for ones that note the signal:
    masking the main thread would not do, as the kernel hands a masked signal to another thread (OpenCV's, Rerun's),
    whose C handler still has the main thread run the Python handler mid-block."""
    stops = (signal.SIGINT, signal.SIGTERM)
    old = {sig: signal.getsignal(sig) for sig in stops}
    # off the main thread no handler can be set; one installed outside Python cannot be put back
    if threading.current_thread() is not threading.main_thread() or None in old.values():
        yield
        return
    held: list[int] = []
    for sig in stops:
        signal.signal(sig, lambda signum, _frame: held.append(signum))
    try:
        yield
    finally:
        for sig, handler in old.items():
            signal.signal(sig, handler)
        for sig in dict.fromkeys(held):
            signal.raise_signal(sig)
