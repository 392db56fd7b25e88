"""The obstacle finder's search for the nearest group of standing pixels, compiled.

Compiled because a frame tries several range bins and each, in numpy, is a dozen small calls (the sort, the sums,
the grid of image cells and its connected components, the percentile). The arithmetic is numpy's, operation for
operation and type for type, so the group is the same pixel for pixel as the numpy form kept as the reference in
tests/longitudinal/test_groups.py. Logarithms and exponentials stay in numpy (its own SIMD functions, which need not
round as the C library's do).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from percept.compiled import kernel, pairwise_sum


@kernel()
def range_bins(k, area):  # pragma: no cover - compiled
    """The points' range bins ``k`` (N,) int64 sorted: ``order`` (a stable argsort), the running sums ``run`` (N + 1,)
    float64 of the points' ``area`` (N,) float32 in that order from 0 (numpy's cumsum), the distinct bins ``bins`` and,
    for each, the slice [los, his) of the sorted points in bins b - 1 .. b + 1."""
    order = np.argsort(k, kind="mergesort")
    n = k.shape[0]
    ks = k[order]
    run = np.empty(n + 1)
    run[0] = 0.0
    for j in range(n):
        # run[j + 1] = area[order[0]] + ... + area[order[j]], left to right
        a = np.float64(area[order[j]])
        run[j + 1] = a if j == 0 else run[j] + a
    m = 0
    for j in range(n):
        if j == 0 or ks[j] != ks[j - 1]:
            m += 1
    bins = np.empty(m, np.int64)
    m = 0
    for j in range(n):
        if j == 0 or ks[j] != ks[j - 1]:
            bins[m] = ks[j]
            m += 1
    los = np.searchsorted(ks, bins - 1, side="left")
    his = np.searchsorted(ks, bins + 1, side="right")
    return order, run, bins, los, his


@kernel()
def first_grounded_blob(cands, los, his, needs, order, u, v, h, area, cell, q, grounded):  # pragma: no cover
    """The first candidate bin c (of ``cands``, indices into ``los``, ``his``, ``needs``) whose points
    ``order[los:his]`` (taken in index order) hold ``needs`` [px] of ``area``, and whose largest blob (by area) of
    image cells ``cell`` [px] square, 8-connected, holds it too with its ``q``-th height percentile below
    ``grounded`` [m]: (1, the blob's point indices). (0, none) when no candidate has one; (-1 - c, none) when the
    largest blob at candidate c is not unique (two of equal area: which one is first is cv2's labelling order's to
    say, so the caller takes it from there)."""
    empty = np.empty(0, np.int64)
    cellf = np.float32(cell)
    for c in range(cands.shape[0]):
        i = cands[c]
        lo, hi, need = los[i], his[i], needs[i]
        near = np.sort(order[lo:hi])
        a_near = area[near]
        if pairwise_sum(a_near, 0, a_near.shape[0]) < need:
            continue
        cu, cv, labels = _cells(near, u, v, cellf)
        count = _label_components(labels)
        best, ties = _largest_label(labels, cu, cv, a_near, count)
        if ties:
            return -1 - c, empty
        blob = _label_points(labels, cu, cv, near, best)
        if pairwise_sum(area[blob], 0, blob.shape[0]) >= need and _percentile(h[blob], q) < grounded:
            return 1, blob
    return 0, empty


@njit(cache=True, error_model="numpy")
def _cells(near, u, v, cellf):  # pragma: no cover - compiled
    """The image cells of the points ``near`` (N,): their columns and rows cu, cv (N,) int64, (u / cell, v / cell) in
    float32 truncated, and a grid (gh, gw) int64 holding -1 at each occupied cell and 0 elsewhere, with one free row
    and column beyond the last occupied ones."""
    nn = near.shape[0]
    cu, cv = np.empty(nn, np.int64), np.empty(nn, np.int64)
    gw, gh = 0, 0
    for j in range(nn):
        cu[j], cv[j] = int(u[near[j]] / cellf), int(v[near[j]] / cellf)
        gw, gh = max(gw, cu[j] + 2), max(gh, cv[j] + 2)
    labels = np.zeros((gh, gw), np.int64)
    for j in range(nn):
        labels[cv[j], cu[j]] = -1
    return cu, cv, labels


@njit(cache=True, error_model="numpy")
def _label_components(labels):  # pragma: no cover - compiled
    """The 8-connected components of the cells marked -1 in ``labels`` (gh, gw) int64 labelled 1, 2, ... in place,
    in the row-major order of their first cell, by flood fill; their count."""
    gh, gw = labels.shape
    stack = np.empty(gh * gw, np.int64)
    count = 0
    for r in range(gh):
        for s in range(gw):
            if labels[r, s] != -1:
                continue
            count += 1
            labels[r, s] = count
            top = 0
            stack[0] = r * gw + s
            while top >= 0:
                p = stack[top]
                top -= 1
                pr, ps = p // gw, p % gw
                for dr in range(-1, 2):
                    for ds in range(-1, 2):
                        rr, ss = pr + dr, ps + ds
                        if 0 <= rr < gh and 0 <= ss < gw and labels[rr, ss] == -1:
                            labels[rr, ss] = count
                            top += 1
                            stack[top] = rr * gw + ss
    return count


@njit(cache=True)
def _largest_label(labels, cu, cv, a_near, count):  # pragma: no cover - compiled
    """The label of the largest of ``count`` blobs by area, each blob's area the points' ``a_near`` (N,) float32
    summed in the points' order in float64 (numpy's bincount with weights), and how many other blobs have that area."""
    sums = np.zeros(count + 1)
    for j in range(cu.shape[0]):
        sums[labels[cv[j], cu[j]]] += np.float64(a_near[j])
    best, ties = 1, 0
    for b in range(2, count + 1):
        if sums[b] > sums[best]:
            best, ties = b, 0
        elif sums[b] == sums[best]:
            ties += 1
    return best, ties


@njit(cache=True)
def _label_points(labels, cu, cv, near, best):  # pragma: no cover - compiled
    """The point indices of ``near`` (N,) whose cell carries the label ``best``, in order."""
    size = 0
    for j in range(near.shape[0]):
        if labels[cv[j], cu[j]] == best:
            size += 1
    blob = np.empty(size, np.int64)
    size = 0
    for j in range(near.shape[0]):
        if labels[cv[j], cu[j]] == best:
            blob[size] = near[j]
            size += 1
    return blob


@njit(cache=True)
def _percentile(x, q):  # pragma: no cover - compiled
    """``np.percentile(x, q)`` of a non-empty float64 or float32 array without NaN, in float64 (quantiles.percentile's
    and percentiles' arithmetic: the neighbours' difference in the array's type, the interpolation in float64)."""
    n = x.shape[0]
    # virtual index i = (n - 1) q / 100
    vq = (n - 1) * (q / 100.0)
    s = np.sort(x)
    if vq >= n - 1:
        return np.float64(s[n - 1])
    lo = int(vq)
    x0, x1 = s[lo], s[lo + 1]
    t = vq - lo
    d = x1 - x0
    return x1 - d * (1 - t) if t >= 0.5 else x0 + d * t


@kernel()
def group_extent(u, v, z, area, blob):  # pragma: no cover - compiled
    """What the finder reports of a group (``blob``: its point indices): the 2nd and 98th percentiles of its columns
    and rows ``u``, ``v`` (N,) float32 (float64, as ``np.percentile`` gives for a list of q), the median of its depths
    ``z`` (N,) float32 (float32, as ``np.median``), and its area (``area`` (N,) float32 summed as ``np.sum``)."""
    n = blob.shape[0]
    us, vs, zs, a = u[blob], v[blob], z[blob], area[blob]
    u0, u1 = _percentile(us, 2), _percentile(us, 98)
    v0, v1 = _percentile(vs, 2), _percentile(vs, 98)
    zs.sort()
    h = n // 2
    # the mean of the middle value or two, as np.mean sums them: from 0, in float32
    zero = np.float32(0.0)
    med = zero + zs[h] if n % 2 else (zero + zs[h - 1] + zs[h]) / np.float32(2.0)
    return u0, u1, v0, v1, med, pairwise_sum(a, 0, n)


def warm_up_groups() -> None:
    """The group search's compiled passes loaded now (compiled once after an install), on a frame's argument types:
    one bin of three points at one pixel, so that no timed frame compiles them."""
    one, idx = np.ones(3, np.float32), np.arange(3, dtype=np.int64)
    order, run, bins, los, his = range_bins(idx * 0, one)
    first_grounded_blob(idx[:1], los, his, np.ones(1), order, one, one, np.zeros(3), one, 8, 5, 1.0)
    group_extent(one, one, one, one, idx)
