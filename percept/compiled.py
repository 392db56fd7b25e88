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


def dispatchers(*modules) -> list:
    """The numba dispatchers of every ``kernel`` defined in ``modules``: what a warm-up check counts the compiled
    signatures of."""
    return [k.dispatcher for m in modules for k in vars(m).values() if hasattr(k, "dispatcher")]


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


@njit(cache=True)
def _pairwise_leaf(a, lo, n):  # pragma: no cover - compiled
    """numpy's sum of a run of at most 128: up to 8 sequentially, more in eight interleaved partial sums."""
    if n < 8:
        res = a.dtype.type(0)
        for i in range(lo, lo + n):
            res += a[i]
        return res
    r0, r1, r2, r3 = a[lo], a[lo + 1], a[lo + 2], a[lo + 3]
    r4, r5, r6, r7 = a[lo + 4], a[lo + 5], a[lo + 6], a[lo + 7]
    i = 8
    while i < n - n % 8:
        r0 += a[lo + i]
        r1 += a[lo + i + 1]
        r2 += a[lo + i + 2]
        r3 += a[lo + i + 3]
        r4 += a[lo + i + 4]
        r5 += a[lo + i + 5]
        r6 += a[lo + i + 6]
        r7 += a[lo + i + 7]
        i += 8
    res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while i < n:
        res += a[lo + i]
        i += 1
    return res


@njit(cache=True)
def pairwise_sum(a, lo, n):  # pragma: no cover - compiled
    """``np.sum`` of ``a[lo:lo + n]`` (1-D, contiguous) bit for bit: numpy's pairwise summation in the array's own
    type (numpy/_core/src/umath/loops_utils.h.src, ``pairwise_sum``): a run longer than 128 is the sum of its two
    halves, split at a multiple of 8. numpy recurses; this walks the same tree with a stack (numba's disk cache is
    not safe for recursive functions)."""
    # tasks (start, length, halves done?) and the partial sums, post-order: left half, right half, then their sum
    starts, lengths, combine = np.empty(128, np.int64), np.empty(128, np.int64), np.empty(128, np.bool_)
    sums = np.empty(64, a.dtype)
    top, filled = 0, 0
    starts[0], lengths[0], combine[0] = lo, n, False
    while top >= 0:
        s, m, c = starts[top], lengths[top], combine[top]
        top -= 1
        if c:
            filled -= 1
            sums[filled - 1] = sums[filled - 1] + sums[filled]
        elif m <= 128:
            sums[filled] = _pairwise_leaf(a, s, m)
            filled += 1
        else:
            half = m // 2
            half -= half % 8
            starts[top + 1], lengths[top + 1], combine[top + 1] = s, m, True
            starts[top + 2], lengths[top + 2], combine[top + 2] = s + half, m - half, False
            starts[top + 3], lengths[top + 3], combine[top + 3] = s, half, False
            top += 3
    # numpy's reduction adds the pairwise sum to its identity, +0 (so that a sum of -0s is +0)
    return a.dtype.type(0) + sums[0]


@njit(cache=True)
def floor_divide(a, b):  # pragma: no cover - compiled
    """``a // b`` for floats of one type, as numpy computes it (``npy_divmod``): (a - fmod(a, b)) / b, one less when
    fmod's sign differs from b's, floored and rounded up from above .5; b != 0."""
    one = b / b  # 1 in b's own type: a Python 1 would turn float32 arithmetic into float64
    mod = np.fmod(a, b)
    div = (a - mod) / b
    if mod != 0 and (b < 0) != (mod < 0):
        div -= one
    fl = np.floor(div)
    if div - fl > one / (one + one):
        fl += one
    return fl


@njit(cache=True, error_model="numpy")
def floor_quotient(a, b):  # pragma: no cover - compiled
    """floor(a / b) of float32 a and b > 0 as an int64, exactly numpy's ``a // b`` (``floor_divide``) wherever the
    multiple of b below a is a float32, as for a corner's grid cell (tests/odometry/test_features_reference.py): the
    quotient in float64, then moved to the multiple q with q b <= a < (q + 1) b, the products exact in float64 for
    whole q under 2^29. No ``fmod``: it would cost more than the rest of the corner selection's pass."""
    a64, b64 = np.float64(a), np.float64(b)
    q = np.floor(a64 / b64)
    if q * b64 > a64:
        q -= 1.0
    elif (q + 1.0) * b64 <= a64:
        q += 1.0
    return np.int64(q)
