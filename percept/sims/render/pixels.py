"""Compiled per-pixel loops of the rasteriser's large patches (numba, cached on disk): the patches one by one over
their boxes, their textures' colours put where they still win, the depth read off the z-buffer and the silhouettes'
summary. The small patches' loops are in ``small_patches.py``.

The arithmetic is that of the vectorised numpy formulas, operation for operation and in their precision (float32 for
1/Z, float64 where numpy promotes), so the images are theirs to the bit: every float32 value is cast explicitly,
because numba (unlike numpy) widens float32 with a float64 literal to float64. ``fragments.py`` holds what OpenCV
does (texture warps) and the order of the passes.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from percept.compiled import kernel

f32 = np.float32


@njit(cache=True)
def _below(xa, xb, s, t, tol):  # pragma: no cover - compiled
    """Of the columns [xa, xb), the range where s x + t <= tol can hold, widened by a column each way; all of them
    when that cannot be told (the bound is not finite)."""
    if s == 0.0:
        return (xa, xa) if t > tol else (xa, xb)
    q = (tol - t) / s
    if not np.isfinite(q):
        return xa, xb
    # clamped to the columns, so that the conversion to an integer cannot overflow
    q = min(max(q, xa - 2.0), xb + 2.0)
    if s > 0.0:
        return xa, min(xb, int(np.floor(q)) + 2)
    return max(xa, int(np.ceil(q)) - 1), xb


@njit(cache=True)
def _near_columns(xa, xb, ma0, ay, mb0, by, mc0, cy, inv_near):  # pragma: no cover - compiled
    """The columns of [xa, xb) of one row of a patch crossing the near plane outside which its exact test (float32
    a' = ma0 x + ay, b' likewise, c = mc0 x + cy: max(|a'|, |b'|) <= c, 0 < c < ``inv_near``) cannot pass: each of
    a' - c, -a' - c, b' - c, -b' - c, -c and c - inv_near is linear in x, and the float32 rounding of the test is
    below tol, 1e-5 of the terms' magnitudes (float32 rounds to 6e-8 of them), so no pixel the test would pass is
    cut. A disc (a'^2 + b'^2 <= c^2) lies within the same bounds."""
    m = float(max(abs(xa), abs(xb)))
    a0, a, b0, b, c0, c = float(ma0), float(ay), float(mb0), float(by), float(mc0), float(cy)
    for s, t in ((a0 - c0, a - c), (-a0 - c0, -a - c), (b0 - c0, b - c), (-b0 - c0, -b - c), (-c0, -c),
                 (c0, c - float(inv_near))):
        tol = 1e-5 * (m * (abs(a0) + abs(b0) + abs(c0)) + abs(a) + abs(b) + abs(c) + float(inv_near))
        xa, xb = _below(xa, xb, s, t, tol)
        if xb <= xa:
            return xa, xa
    return xa, xb


@njit(cache=True, inline="always")
def _inside_near(ap, bp, c, ellipse, inv_near):  # pragma: no cover - compiled
    """The exact inside test of a pixel of a patch crossing the near plane: a' = ``ap``, b' = ``bp`` and c = 1/Z
    (float32) inside the quad, max(|a'|, |b'|) <= c, or the ``ellipse``, a'^2 + b'^2 <= c^2, with 0 < c <
    ``inv_near``."""
    if ellipse:
        inside = ap * ap + bp * bp <= c * c
    else:
        inside = max(abs(ap), abs(bp)) <= c
    return inside and c < inv_near and c > 0


@njit(cache=True)
def _silhouette_bound(order, obj_id, x0, x1, y0, y1):  # pragma: no cover - compiled
    """How many pixels the boxes of the patches ``order`` with an object id > 0 cover (with repeats): every inside
    pixel of a patch lies in its box, so this bounds the silhouettes' pixels."""
    bound = 0
    for k in range(len(order)):
        i = order[k]
        if obj_id[i] > 0:
            bound += (x1[i] - x0[i]) * (y1[i] - y0[i])
    return bound


@kernel()
def big_patches(wbuf, ids, em, img, winner, order, x0, x1, y0, y1, ma, mb, mc, ellipse, span_row, los, his,
                obj_id, emissive, color, defer, want_sil, inv_near):  # pragma: no cover - compiled
    """Patches ``order[k]`` one by one over their boxes, z-tested against ``wbuf`` (H, W) float32 and written to it,
    to ``ids`` and ``em`` (empty arrays to skip) and to ``img`` (H, W, 3) uint8 in the colour ``color`` (float32,
    truncated), except the patches with ``defer`` (textured), coloured afterwards where ``winner`` (H, W), the
    order index k of the last patch that won each pixel, still names them. ``span_row[i]``: the patch's first row in
    ``los``, ``his`` (its inside columns per box row), or -1 for a patch crossing the near plane (the exact test per
    pixel, c < ``inv_near``). Returns the pixels each k holds at the end, the row after the last one in which it won
    a pixel and, when ``want_sil``, every inside pixel (flat index) of the patches with an object id > 0 and that id."""
    W = wbuf.shape[1]
    has_ids, has_em = ids.size > 0, em.size > 0
    held, ends = np.zeros(len(order), np.int64), np.zeros(len(order), np.int64)
    # the silhouettes' buffers are allocated once, never grown in the loop (an array reassigned in the pixel loop
    # keeps LLVM from optimising the loop)
    bound = _silhouette_bound(order, obj_id, x0, x1, y0, y1) if want_sil else 0
    sil_pix, sil_oid = np.empty(bound, np.int32), np.empty(bound, np.int32)
    ns = 0
    for k in range(len(order)):
        i = order[k]
        oid = obj_id[i]
        sil = want_sil and oid > 0
        mc0, mc1, mc2 = f32(mc[i, 0]), f32(mc[i, 1]), f32(mc[i, 2])
        ma0, ma1, ma2 = f32(ma[i, 0]), f32(ma[i, 1]), f32(ma[i, 2])
        mb0, mb1, mb2 = f32(mb[i, 0]), f32(mb[i, 1]), f32(mb[i, 2])
        r = span_row[i]
        for y in range(y0[i], y1[i]):
            fy = f32(y)
            # c(u, v) = 1/Z = mc0 u + mc1 v + mc2
            cy = mc1 * fy + mc2
            ay = ma1 * fy + ma2
            by = mb1 * fy + mb2
            if r >= 0:  # the row's span: every pixel in it is inside
                xa, xb = max(x0[i], los[r + y - y0[i]]), min(x1[i], his[r + y - y0[i]] + 1)
            else:  # the columns where the exact test can pass (a disc lies within its quad)
                xa, xb = _near_columns(x0[i], x1[i], ma0, ay, mb0, by, mc0, cy, inv_near)
            for x in range(xa, xb):
                fx = f32(x)
                c = mc0 * fx + cy
                if r < 0 and not _inside_near(ma0 * fx + ay, mb0 * fx + by, c, ellipse[i], inv_near):
                    continue
                if sil:
                    sil_pix[ns] = y * W + x
                    sil_oid[ns] = oid
                    ns += 1
                if not c > wbuf[y, x]:
                    continue
                wbuf[y, x] = c
                if has_ids:
                    ids[y, x] = oid
                if has_em:
                    em[y, x] = f32(emissive[i])
                if winner[y, x] >= 0:
                    held[winner[y, x]] -= 1
                winner[y, x] = k
                held[k] += 1
                ends[k] = y + 1
                if not defer[i]:
                    for ch in range(3):
                        img[y, x, ch] = np.uint8(color[i, ch])
    return held, ends, sil_pix[:ns], sil_oid[:ns]


@kernel()
def clear_boxes(winner, order, x0, x1, y0, ends):  # pragma: no cover - compiled
    """Set ``winner`` back to -1 over each box k of ``big_patches`` (patch ``order[k]``'s columns x0..x1, rows
    y0 up to ``ends[k]``, the row after the last one it won a pixel in): everywhere it wrote."""
    for k in range(len(order)):
        i = order[k]
        for y in range(y0[i], ends[k]):
            for x in range(x0[i], x1[i]):
                winner[y, x] = -1


@kernel()
def zbuffer_depth(inv, base, background):  # pragma: no cover - compiled
    """Depth (H, W) float32 [m]: 1 / ``inv`` wherever a patch won the z-test (``inv`` differs from ``base``, what
    the z-buffer held before any patch), else ``background``'s (float32 1/x, as numpy divides; every pixel divided, no
    test for zero in the loop: ``kernel``'s numpy error model, and the quotient is not taken where inv is base's)."""
    out = np.empty_like(background)
    for y in range(inv.shape[0]):
        for x in range(inv.shape[1]):
            d = f32(1.0) / inv[y, x]
            out[y, x] = d if inv[y, x] != base[y, x] else background[y, x]
    return out


@kernel()
def put_albedo(img, alb, lut, winner, k, x0, y0):  # pragma: no cover - compiled
    """``img`` (H, W, 3) uint8 = ``lut[alb]`` (the colour map (256, 1, 3) uint8 of the albedo ``alb`` (h, w) uint8
    warped over the box from (x0, y0)) wherever ``winner`` names patch k."""
    for r in range(alb.shape[0]):
        for c in range(alb.shape[1]):
            if winner[y0 + r, x0 + c] == k:
                a = alb[r, c]
                for ch in range(3):
                    img[y0 + r, x0 + c, ch] = lut[a, 0, ch]


@kernel()
def silhouette_stats(pix, W, ids, obj_id):  # pragma: no cover - compiled
    """Of flat pixel indices ``pix`` (N,) int32 (row * W + col, N >= 1, repeats allowed) of one object: the tight
    box (u0, v0, u1, v1) (u1, v1 exclusive), how many distinct pixels, and how many of them show ``obj_id`` in the
    flat id map ``ids`` (empty: none counted)."""
    lo, hi = pix.min(), pix.max()
    base = (lo // W) * W
    mark = np.zeros(hi - base + 1, np.bool_)
    u0, v0, u1, v1 = W, hi // W, -1, -1
    count, seen = 0, 0
    for p in pix:
        if not mark[p - base]:
            mark[p - base] = True
            count += 1
            v, u = p // W, p % W
            u0, u1, v0, v1 = min(u0, u), max(u1, u), min(v0, v), max(v1, v)
            if ids.size > 0 and ids[p] == obj_id:
                seen += 1
    return u0, v0, u1 + 1, v1 + 1, count, seen
