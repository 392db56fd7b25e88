"""Quantiles of the short arrays a detection is measured from."""

from __future__ import annotations

import numpy as np


def quantiles(values: np.ndarray, q):
    """``np.quantile(values, q)`` with its default (linear) method, bit for bit and of the same dtype, for a 1-D array
    ``values`` (n >= 1) and ``q`` a number or a sequence in [0, 1]: a sort and one interpolation, where numpy's
    general machinery costs about four times as much on the few hundred points of a car (its ``_lerp`` is copied: from
    the lower of the two order statistics when gamma < 0.5, from the upper one otherwise)."""
    s = np.sort(values)
    scalar = np.ndim(q) == 0
    # virtual index h = (n - 1) q, between order statistics i = floor(h) and j = min(i + 1, n - 1); gamma = h - i
    h = (len(s) - 1) * np.asarray(q, dtype=float)
    lo = np.floor(h)
    i = lo.astype(np.intp)
    j = np.minimum(i + 1, len(s) - 1)
    # numpy takes a scalar q as a weak Python float, so the arithmetic stays in the array's dtype
    g = float(h - lo) if scalar else h - lo
    a, b = s[i], s[j]
    diff = b - a
    if scalar:
        return b - diff * (1 - g) if g >= 0.5 else a + diff * g
    return np.where(g >= 0.5, b - diff * (1 - g), a + diff * g)


def median(values: np.ndarray):
    """``np.median(values)``, bit for bit and of the same dtype, for a 1-D array ``values`` (n >= 1) without NaNs: one
    partition and the mean of the middle one or two, where numpy's general reduction costs several times as much on
    a face's few hundred points."""
    n = len(values)
    k = n // 2
    if n % 2:
        return np.partition(values, k)[k]
    p = np.partition(values, (k - 1, k))
    # the mean of the two middle order statistics, summed in the array's dtype as numpy's mean does
    return (p[k - 1] + p[k]) / 2
