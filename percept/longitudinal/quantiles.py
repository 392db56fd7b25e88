"""Percentiles and medians of the small arrays of one frame, equal bit for bit to numpy's, without the generic
machinery of ``np.percentile`` and ``np.median`` (axes, NaN checks, dtype rules), which costs more than the work on
a 1-D array of a few hundred finite values.

numpy's default ("linear", Hyndman & Fan's method 7): the value at virtual index i = (n - 1) q of the sorted
array, interpolated between its neighbours (numpy.lib._function_base_impl._quantile and _lerp). A scalar q gives
the array's dtype (numpy treats it as a weak Python float); a list of q gives float64.
"""

from __future__ import annotations

import numpy as np


def _linear(a: np.ndarray, q: float, weak: bool):
    """numpy's linear q-th percentile of ``a`` (q in [0, 100]); ``weak``: in the array's dtype (a scalar q), else
    float64 (a list of q)."""
    n = a.size
    # virtual index i = (n - 1) q, q in [0, 1]
    v = (n - 1) * np.true_divide(q, 100)
    if v >= n - 1:
        top = np.partition(a, -1)[-1]
        return top if weak else np.float64(top)
    lo = int(v)
    p = np.partition(a, (lo, lo + 1))
    x0, x1 = p[lo], p[lo + 1]
    t = float(v - lo) if weak else np.float64(v - lo)
    d = x1 - x0
    # numpy's _lerp: x0 + d t below t = 0.5, x1 - d (1 - t) from it (exact at both ends)
    return x1 - d * (1 - t) if t >= 0.5 else x0 + d * t


def percentile(a: np.ndarray, q: float):
    """``np.percentile(a, q)`` for a non-empty 1-D float array without NaN and a scalar q in [0, 100]."""
    return _linear(a, q, weak=True)


def percentiles(a: np.ndarray, qs: tuple[float, ...]) -> list[np.float64]:
    """``list(np.percentile(a, qs))`` for a non-empty 1-D float array without NaN and a sequence of q."""
    return [_linear(a, q, weak=False) for q in qs]


def median(a: np.ndarray):
    """``np.median(a)`` for a non-empty 1-D float array without NaN: the middle value, or the mean of the two.
    numpy takes that mean with ``np.mean``: its sum starts from 0 (so a -0.0 comes out as 0.0) and the result keeps
    the array's dtype, which the scalar arithmetic below does as well."""
    n, h = a.size, a.size // 2
    if n % 2:
        # mean of one value x: (0 + x) / 1
        return 0.0 + np.partition(a, h)[h]
    p = np.partition(a, (h - 1, h))
    # mean of two: (0 + x0 + x1) / 2
    return (0.0 + p[h - 1] + p[h]) / 2
