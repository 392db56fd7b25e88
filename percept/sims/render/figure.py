"""The primitives a pedestrian's figure is built from, compiled (numba): view-facing tapered limbs, view-facing
discs and boxes, collected as rows of a buffer, then lowered onto the ground and packed as the renderer's patches.

A figure is some fifty thousand tuple operations, too many for the interpreter in every frame. These functions run
compiled, and do the float64 operations the interpreter would do, in the same order:
``vec3``'s tuple functions, Python's ``min``/``max`` (which keep the first of equal arguments; ``pymin``,
``pymax``), and no ``math.hypot`` of two non-zero numbers (the C library's, which numba calls, differs from
CPython's in the last bit for about 0.6% of arguments; see ``pedestrian._body``). So a figure is the same to the
bit; ``tests/sims/test_render_kernels.py`` builds figures with and without the compiler and compares them.

A buffer row (``ROW`` float64 columns): ``[kind, ...]``; kind 0 or 1 is a patch (quad or ellipse outline)
``origin (3), e1 (3), e2 (3), colour (3)``; kind 2 a box ``centre (3), unit axes x, y, z (3 × 3), size (3),
colour (3)``. World frame [m], BGR 0..255 before shading.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, types

from .patches import SUN_DIR, box_faces
from .vec3 import UP, cross, dot, madd, mul, norm, sub, vec

__all__ = ["BOX", "ELLIPSE", "QUAD", "ROW", "box", "disc", "limb", "packed", "pymax", "pymin", "scaled", "toward_view"]

QUAD, ELLIPSE, BOX = 0, 1, 2
ROW = 19
SUN = vec(SUN_DIR)
"""Light direction (world) for the lit and shadowed halves of a limb: the renderer's sun."""

# Explicit signatures for the functions called with constants (kinds, caps): numba would otherwise compile one
# version per combination of those constants' values
_V3, _F, _I, _B = types.UniTuple(types.float64, 3), types.float64, types.int64, types.boolean
_ROWS = types.float64[:, ::1]


@njit(cache=True)
def pymin(a: float, b: float) -> float:
    """Python's ``min(a, b)``: ``a`` unless ``b`` is smaller (so min(0.0, -0.0) is 0.0)."""
    return b if b < a else a


@njit(cache=True)
def pymax(a: float, b: float) -> float:
    """Python's ``max(a, b)``: ``a`` unless ``b`` is larger."""
    return b if b > a else a


@njit(cache=True)
def scaled(colour, k: float):
    """``colour`` (BGR) times k, each channel at most 255."""
    return (pymin(255.0, colour[0] * k), pymin(255.0, colour[1] * k), pymin(255.0, colour[2] * k))


@njit(cache=True)
def toward_view(view, p, bias: float):
    """``p`` moved ``bias`` [m] horizontally towards the viewer ``view``; ``p`` itself when ``bias`` is 0."""
    if bias == 0.0:
        return p
    # p + bias d / |d|, d the horizontal direction from p to the viewer
    d = (view[0] - p[0], view[1] - p[1], 0.0)
    n = norm(d) + 1e-12
    return (p[0] + bias * d[0] / n, p[1] + bias * d[1] / n, p[2] + bias * d[2] / n)


@njit(_I(_ROWS, _I, _I, _V3, _V3, _V3, _V3), cache=True)
def _put(rows, n: int, kind: int, a, b, c, colour) -> int:
    """Row ``n`` = (kind, a, b, c, colour), each a 3-tuple; returns n + 1."""
    if n >= rows.shape[0]:
        raise IndexError("pedestrian figure: more parts than its row buffer holds")
    rows[n, 0] = kind
    for j in range(3):
        rows[n, 1 + j] = a[j]
        rows[n, 4 + j] = b[j]
        rows[n, 7 + j] = c[j]
        rows[n, 10 + j] = colour[j]
    return n + 1


@njit(_I(_ROWS, _I, _V3, _V3, _F, _F, _V3, _F), cache=True)
def disc(rows, n: int, view, c, ry: float, rx: float, colour, bias: float) -> int:
    """A view-facing ellipse centred at c (moved ``bias`` towards the viewer): half-height ry, half-width rx."""
    c = toward_view(view, c, bias)
    d = sub(view, c)
    nd = norm(d) + 1e-12
    d = (d[0] / nd, d[1] / nd, d[2] / nd)
    right = cross(UP, d)
    nr = norm(right) + 1e-12
    right = (right[0] / nr, right[1] / nr, right[2] / nr)
    upv = cross(d, right)
    return _put(rows, n, ELLIPSE, madd(madd(c, -rx, right), -ry, upv), mul(2 * rx, right), mul(2 * ry, upv),
                colour)


@njit(cache=True)
def _frame(view, p0, p1):
    """A limb's axis p1 - p0, the unit vector across it facing ``view``, and whether that exists."""
    axis = sub(p1, p0)
    side = cross(axis, sub(view, ((p0[0] + p1[0]) / 2, (p0[1] + p1[1]) / 2, (p0[2] + p1[2]) / 2)))
    ns = norm(side)
    if ns < 1e-9:
        return axis, side, False
    return axis, (side[0] / ns, side[1] / ns, side[2] / ns), True


@njit(_I(_ROWS, _I, _V3, _V3, _V3, _F, _F, _V3, _V3, _V3, _B, _B), cache=True)
def _halves(rows, n: int, view, p0, p1, r0: float, r1: float, axis, side, colour, cap0: bool, cap1: bool) -> int:
    """A limb wider at p0 (r0 >= r1): each half (either side of the axis) a rectangle plus a parallelogram for the
    taper, the half facing the sun a little brighter than the other; then the caps."""
    sun = dot(side, SUN)
    lit = 1.0 if sun >= 0 else -1.0
    for sgn in (lit, -lit):
        s = mul(sgn, side)
        k = 1.0 + (0.13 * abs(sun) + 0.04) * (1 if sgn == lit else -1)
        col = scaled(colour, k)
        # the lit half overlaps the centre line by a little and sits 2 mm nearer, so it wins there
        over, nb = (0.15 * r1, 0.002) if sgn == lit else (0.0, 0.0)
        near = toward_view(view, p0, nb)
        n = _put(rows, n, QUAD, madd(near, -over, s), mul(r1 + over, s), axis, col)
        if r0 - r1 > 1e-6:
            w = pymin(r0 - r1 + 0.1 * r1, r1)
            e2 = madd(axis, r1 - r0, s)
            n = _put(rows, n, QUAD, madd(near, r0, s), mul(-w, s), e2, col)
    if cap0:
        n = disc(rows, n, view, p0, r0, r0, colour, 0.0)
    if cap1:
        n = disc(rows, n, view, p1, r1, r1, colour, 0.0)
    return n


@njit(_I(_ROWS, _I, _V3, _V3, _V3, _F, _F, _V3, _F, _B, _B), cache=True)
def limb(rows, n: int, view, p0, p1, r0: float, r1: float, colour, bias: float, cap0: bool, cap1: bool) -> int:
    """A tapered view-facing quad from p0 (half-width r0) to p1 (half-width r1) with round caps where asked; both
    ends first moved ``bias`` towards the viewer. Returns the next free row."""
    p0 = toward_view(view, p0, bias)
    p1 = toward_view(view, p1, bias)
    while True:
        axis, side, ok = _frame(view, p0, p1)
        if not ok:
            return n
        if r0 < r1:  # build from the wide end
            p0, p1, r0, r1, axis, cap0, cap1 = p1, p0, r1, r0, (-axis[0], -axis[1], -axis[2]), cap1, cap0
        if r0 <= 1.9 * r1:
            return _halves(rows, n, view, p0, p1, r0, r1, axis, side, colour, cap0, cap1)
        # too steep a taper for one rectangle + parallelogram per half: the wide part (a taper of 1.8), then the rest
        rm = r0 / 1.8
        pm = madd(p0, (r0 - rm) / (r0 - r1), axis)
        axis_w, side_w, ok = _frame(view, p0, pm)
        if ok:
            n = _halves(rows, n, view, p0, pm, r0, rm, axis_w, side_w, colour, cap0, False)
        p0, r0, cap0 = pm, rm, False


@njit(cache=True)
def box(rows, n: int, centre, axes, size, colour) -> int:
    """A box with its bottom: ``centre``, ``axes`` (unit x, y, z of the box), ``size`` along them [m]."""
    n = _put(rows, n, BOX, centre, axes[0], axes[1], axes[2])
    for j in range(3):
        rows[n - 1, 13 + j] = size[j]
        rows[n - 1, 16 + j] = colour[j]
    return n


@njit(cache=True)
def _lowest_z(rows, n: int) -> float:
    """Lowest z [m] of the first n rows' shapes."""
    z = math.inf
    for i in range(n):
        r = rows[i]
        if r[0] == BOX:
            # the centre less the half extents' heights along each axis
            z = pymin(z, r[3] - (abs(r[13] / 2 * r[6]) + abs(r[14] / 2 * r[9]) + abs(r[15] / 2 * r[12])))
        elif r[0] == ELLIPSE:
            # e1 is horizontal (a disc's e1[2] is ±0), where numba's hypot is CPython's: |e2[2]|
            z = pymin(z, r[3] + 0.5 * (r[6] + r[9]) - 0.5 * math.hypot(r[6], r[9]))
        else:
            z = pymin(z, r[3] + pymin(0.0, r[6]) + pymin(0.0, r[9]))
    return z


@njit(cache=True)
def packed(rows, n: int, oid: int) -> np.ndarray:
    """The first n rows lowered so that the lowest point is at z = 0, packed as ``PatchBatch.pack`` packs them:
    (P, 19) float64; patches two-sided, boxes as six one-sided faces (outwards, as ``PatchBuilder.box`` orients
    them); all shaded, untextured (-1), texture repeat (1, 1), object id ``oid``."""
    dz = -_lowest_z(rows, n)
    count = 0
    for i in range(n):
        count += 6 if rows[i, 0] == BOX else 1
    out = np.empty((count, 19))
    fid = float(oid)
    k = 0
    for i in range(n):
        r = rows[i]
        if r[0] == BOX:
            centre = (r[1] + 0.0, r[2] + 0.0, r[3] + dz)
            axes = ((r[4], r[5], r[6]), (r[7], r[8], r[9]), (r[10], r[11], r[12]))
            for f, a, b in box_faces(centre, axes, (r[13], r[14], r[15])):
                k = _out_row(out, k, f, a, b, r[16:19], (-1.0, 0.0, fid, 0.0, 1.0, 1.0, 1.0))
        else:
            o = (r[1] + 0.0, r[2] + 0.0, r[3] + dz)
            k = _out_row(out, k, o, (r[4], r[5], r[6]), (r[7], r[8], r[9]), r[10:13],
                         (-1.0, r[0], fid, 1.0, 1.0, 1.0, 1.0))
    return out


@njit(cache=True)
def _out_row(out, k: int, o, e1, e2, colour, tail) -> int:
    """Packed row k = (o, e1, e2, colour, tail) (3, 3, 3, 3 and 7 values); returns k + 1."""
    for j in range(3):
        out[k, j] = o[j]
        out[k, 3 + j] = e1[j]
        out[k, 6 + j] = e2[j]
        out[k, 9 + j] = colour[j]
    for j in range(7):
        out[k, 12 + j] = tail[j]
    return k + 1
