"""Compiled per-patch loops of ``raster.prepare`` (numba, cached on disk): culling and projecting each patch into
one camera, and the affine rows of its inverse homography.

Float64 throughout, with the operations in the order of the vectorised numpy formulas (cross and dot products are
``vec3``'s; rows of four summed left to right, as numpy sums them), so the prepared patches are those formulas' to
the bit.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from percept.compiled import kernel

from .vec3 import cross, dot


@njit(cache=True)
def _corners(O, E1, E2, i, C, z):  # pragma: no cover - compiled
    """Patch i's corners o, o + e1, o + e1 + e2, o + e2 into ``C`` (4, 3) and their depths into ``z`` (4,)."""
    for a in range(3):
        C[0, a] = O[i, a]
        C[1, a] = O[i, a] + E1[i, a]
        C[2, a] = (O[i, a] + E1[i, a]) + E2[i, a]
        C[3, a] = O[i, a] + E2[i, a]
    for k in range(4):
        z[k] = C[k, 2]


@njit(cache=True)
def _outline(C, z, near, cut, fx, fy, cx, cy, pu, pv):  # pragma: no cover - compiled
    """The pixels (``pu``, ``pv``) of the corners ``C`` (depths ``z``) in front of the ``near`` plane and, when the
    plane cuts the patch (``cut``), of its edges' crossings with it: the polygon clipped at z = near. Returns how
    many there are."""
    n = 0
    for k in range(4):
        if z[k] >= near:
            # u = fx x / z + cx, v = fy y / z + cy
            pu[n] = fx * C[k, 0] / C[k, 2] + cx
            pv[n] = fy * C[k, 1] / C[k, 2] + cy
            n += 1
    if cut:
        # the edge crossings a + (near - z_a)/(z_b - z_a) (b - a)
        for k in range(4):
            j = (k + 1) % 4
            if (z[k] - near) * (z[j] - near) < 0:
                f = (near - z[k]) / (z[j] - z[k])
                x = C[k, 0] + f * (C[j, 0] - C[k, 0])
                y = C[k, 1] + f * (C[j, 1] - C[k, 1])
                zz = C[k, 2] + f * (C[j, 2] - C[k, 2])
                pu[n] = fx * x / zz + cx
                pv[n] = fy * y / zz + cy
                n += 1
    return n


@njit(cache=True)
def _pixel_box(pu, pv, n, W, H, box, m):  # pragma: no cover - compiled
    """Row m of ``box``: the pixel centres x0 <= k < x1, y0 <= k < y1 within the bounds of the first n points
    (``pu``, ``pv``), clipped to the W x H image."""
    umin, umax, vmin, vmax = pu[0], pu[0], pv[0], pv[0]
    for k in range(1, n):
        umin, umax = min(umin, pu[k]), max(umax, pu[k])
        vmin, vmax = min(vmin, pv[k]), max(vmax, pv[k])
    # pixel centres k with umin <= k <= umax
    box[m, 0] = np.int64(min(max(np.ceil(umin), 0.0), W))
    box[m, 1] = np.int64(min(max(np.floor(umax) + 1.0, 0.0), W))
    box[m, 2] = np.int64(min(max(np.ceil(vmin), 0.0), H))
    box[m, 3] = np.int64(min(max(np.floor(vmax) + 1.0, 0.0), H))


@njit(cache=True)
def _area_width(pu, pv):  # pragma: no cover - compiled
    """Projected area (shoelace) and width = area / longest side [px] of the quad of the first four points."""
    s, longest = 0.0, 0.0
    for k in range(4):
        j = (k + 1) % 4
        s += pu[k] * pv[j] - pu[j] * pv[k]
        longest = max(longest, (pu[k] - pu[j]) ** 2 + (pv[k] - pv[j]) ** 2)
    area = 0.5 * abs(s)
    return area, area / np.sqrt(longest)


@kernel()
def project_patches(O, E1, E2, two_sided, fx, fy, cx, cy, W, H, near):  # pragma: no cover - compiled
    """Patches (origin ``O``, sides ``E1``, ``E2``: (P, 3) in the camera frame) seen from the front
    (or ``two_sided``) and not wholly behind the ``near`` plane: their indices and, per kept patch, the pixel box
    x0, x1, y0, y1 (centres x0 <= k < x1), the nearest depth, whether the near plane cuts it, and its projected
    area and width [px] (NaN when cut)."""
    P = len(O)
    idx, box = np.empty(P, np.int64), np.empty((P, 4), np.int64)
    zmin, crossing = np.empty(P), np.empty(P, np.bool_)
    area, width = np.empty(P), np.empty(P)
    C, z = np.empty((4, 3)), np.empty(4)
    pu, pv = np.empty(8), np.empty(8)
    m = 0
    for i in range(P):
        o, e1, e2 = (O[i, 0], O[i, 1], O[i, 2]), (E1[i, 0], E1[i, 1], E1[i, 2]), (E2[i, 0], E2[i, 1], E2[i, 2])
        # back-face test: a face is seen from the front when n·(o - camera) < 0, n = e1 x e2, the camera the origin
        if not (dot(cross(e1, e2), o) < 0 or two_sided[i]):
            continue
        _corners(O, E1, E2, i, C, z)
        if not max(max(z[0], z[1]), max(z[2], z[3])) > near:
            continue
        zm = min(min(z[0], z[1]), min(z[2], z[3]))
        cut = zm < near
        n = _outline(C, z, near, cut, fx, fy, cx, cy, pu, pv)
        _pixel_box(pu, pv, n, W, H, box, m)
        idx[m], zmin[m], crossing[m] = i, zm, cut
        if cut:
            area[m] = width[m] = np.nan
        else:
            area[m], width[m] = _area_width(pu, pv)
        m += 1
    return idx[:m], box[:m], zmin[:m], crossing[:m], area[:m], width[:m]


@kernel()
def inverse_rows(o, e1, e2, drawable, fx, fy, cx, cy):  # pragma: no cover - compiled
    """Per patch (camera frame, (P, 3)) with ``drawable``: A = K [e1 e2 o] and the affine rows of a' = 2 s/Z - 1/Z,
    b' = 2 t/Z - 1/Z, c = 1/Z from A^-1 = (a2 x a3, a3 x a1, a1 x a2) / det; patches whose A is singular are
    dropped. Returns the kept indices and their rows ma, mb, mc (n, 3)."""
    P = len(o)
    sel = np.empty(P, np.int64)
    ma = np.empty((P, 3))
    mb = np.empty((P, 3))
    mc = np.empty((P, 3))
    m = 0
    for i in range(P):
        if not drawable[i]:
            continue
        a1 = (fx * e1[i, 0] + cx * e1[i, 2], fy * e1[i, 1] + cy * e1[i, 2], e1[i, 2])
        a2 = (fx * e2[i, 0] + cx * e2[i, 2], fy * e2[i, 1] + cy * e2[i, 2], e2[i, 2])
        a3 = (fx * o[i, 0] + cx * o[i, 2], fy * o[i, 1] + cy * o[i, 2], o[i, 2])
        r0, r1, r2 = cross(a2, a3), cross(a3, a1), cross(a1, a2)
        det = dot(a1, r0)
        scale = np.sqrt(dot(a1, a1) * dot(a2, a2) * dot(a3, a3))
        if not abs(det) > 1e-9 * scale:
            continue
        for a in range(3):
            m0, m1, m2 = r0[a] / det, r1[a] / det, r2[a] / det
            ma[m, a] = 2 * m0 - m2
            mb[m, a] = 2 * m1 - m2
            mc[m, a] = m2
        sel[m] = i
        m += 1
    return sel[:m], ma[:m], mb[:m], mc[:m]
