"""What the renderer's compiled kernels (numba) need from Python around them."""

from __future__ import annotations

import functools
from typing import Callable


def interruptible(kernel: Callable) -> Callable:
    """``kernel`` (a numba dispatcher that returns arrays), with Ctrl-C raised as KeyboardInterrupt.

    A SIGINT that lands while a kernel runs is handled by Python's signal handler during the boxing of the
    kernel's results, which numba does not check; CPython then reports the call as SystemError ("returned a result
    with an exception set") caused, through more SystemErrors, by the KeyboardInterrupt, which the commands' Ctrl-C
    handling would not recognise. Kernels that return nothing are not affected. The dispatcher itself is
    ``.dispatcher``."""

    @functools.wraps(kernel)
    def call(*args):
        try:
            return kernel(*args)
        except SystemError as e:
            # the KeyboardInterrupt is at the end of a chain of SystemErrors (each layer of numba's boxing)
            cause = e.__cause__
            while isinstance(cause, SystemError):
                cause = cause.__cause__
            if isinstance(cause, KeyboardInterrupt):
                raise KeyboardInterrupt from None
            raise

    call.dispatcher = kernel
    return call
