"""percept's compiled kernels (numba; the renderer's and HOG's window sums): one decorator for every kernel Python
calls, ``kernel``.

A kernel is compiled the first time it is called with new argument types and cached on disk (``cache=True``),
and it raises Ctrl-C as KeyboardInterrupt: a SIGINT that lands while a kernel runs is handled by Python's signal
handler while numba boxes the kernel's results, which numba does not check, and CPython then reports the call as
a chain of SystemErrors ("returned a result with an exception set") that ends in the KeyboardInterrupt, which the
commands' Ctrl-C handling would not recognise. Functions only called from compiled code (helpers) are
``numba.njit(cache=True)`` alone (with ``error_model="numpy"`` as well where a helper's own loop divides).
"""

from __future__ import annotations

import functools
from typing import Callable

import numpy as np
from numba import njit


def optional(a: np.ndarray | None, dtype, ndim: int = 2) -> np.ndarray:
    """``a``, or an empty array of that dtype and rank when it is None: how a kernel is told a map (ids, lamp map)
    is absent (it tests ``.size > 0``), since numba types None apart from an array."""
    return np.zeros((0,) * ndim, dtype) if a is None else a


def kernel(**options) -> Callable[[Callable], Callable]:
    """``@kernel(...)``: ``numba.njit(cache=True, error_model="numpy", **options)``, called through a wrapper that
    turns the SystemError chain of an interrupted call back into KeyboardInterrupt. The dispatcher itself is
    ``.dispatcher``.

    numpy's error model, not numba's default (Python's): a float division by zero gives inf or nan as IEEE 754 says
    instead of raising, so that a loop that divides has no test in it and can be vectorised (the renderer's depth
    from the z-buffer, the HOG blocks' norms). Every kernel guards the divisions whose divisor can be zero itself;
    where none is zero the results are the same under either model."""

    def wrap(fn: Callable) -> Callable:
        dispatcher = njit(cache=True, **{"error_model": "numpy", **options})(fn)

        @functools.wraps(fn)
        def call(*args):
            try:
                return dispatcher(*args)
            except SystemError as e:
                cause = e.__cause__
                while isinstance(cause, SystemError):
                    cause = cause.__cause__
                if isinstance(cause, KeyboardInterrupt):
                    raise KeyboardInterrupt from None
                raise

        call.dispatcher = dispatcher
        return call
    return wrap
