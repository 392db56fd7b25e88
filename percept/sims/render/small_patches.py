"""Compiled per-pixel loops of the rasteriser's small patches (numba, cached on disk), drawn all at once: one
fragment per inside pixel of their row spans, z-tested together, the winners' texel coordinates and their shading.

The arithmetic is that of the vectorised numpy formulas, operation for operation and in their precision (float32 for
1/Z and texture coordinates, float64 where numpy promotes), so the images are theirs to the bit: every float32
value is cast explicitly, because numba (unlike numpy) widens float32 with a float64 literal to float64.
``fragments.py`` holds what OpenCV does (texel samples) and the order of the passes.
"""

from __future__ import annotations

import numpy as np

from percept.compiled import kernel

f32 = np.float32


@kernel()
def small_fragments(wflat, W, rp, v, first, last, mc, obj_id, want_sil):  # pragma: no cover - compiled
    """One fragment per pixel centre first..last of each span (patch rp, row v): its 1/Z is written to ``wflat``
    where it is the largest (the z-buffer). Returns the winners (fragments whose 1/Z is the pixel's largest;
    equal ones are all kept): pixel, span, offset k along the span and 1/Z; and, when ``want_sil``, every
    fragment's pixel and object id for the patches with an id > 0."""
    total = 0
    for s in range(len(rp)):
        total += max(last[s] - first[s] + 1, 0)
    fpix = np.empty(total, np.int32)
    fspan = np.empty(total, np.int32)
    fk = np.empty(total, np.float32)
    fc = np.empty(total, np.float32)
    m = 0
    for s in range(len(rp)):
        n = last[s] - first[s] + 1
        if n <= 0:
            continue
        i = rp[s]
        # c at the span's first pixel plus its slope along the row
        c0 = f32(mc[i, 0] * first[s] + mc[i, 1] * v[s] + mc[i, 2])
        slope = f32(mc[i, 0])
        base = np.int32(v[s] * W + first[s])
        for k in range(n):
            kf = f32(k)
            c = c0 + slope * kf
            p = base + k
            fpix[m], fspan[m], fk[m], fc[m] = p, s, kf, c
            if c > wflat[p]:
                wflat[p] = c
            m += 1
    nw = 0
    for f in range(total):
        if fc[f] == wflat[fpix[f]]:
            nw += 1
    wpix = np.empty(nw, np.int32)
    wspan = np.empty(nw, np.int32)
    wk = np.empty(nw, np.float32)
    wc = np.empty(nw, np.float32)
    j = 0
    for f in range(total):
        if fc[f] == wflat[fpix[f]]:
            wpix[j], wspan[j], wk[j], wc[j] = fpix[f], fspan[f], fk[f], fc[f]
            j += 1
    ns = 0
    if want_sil:
        for f in range(total):
            if obj_id[rp[fspan[f]]] > 0:
                ns += 1
    sil_pix = np.empty(ns, np.int32)
    sil_oid = np.empty(ns, np.int32)
    j = 0
    if want_sil:
        for f in range(total):
            o = obj_id[rp[fspan[f]]]
            if o > 0:
                sil_pix[j], sil_oid[j] = fpix[f], o
                j += 1
    return wpix, wspan, wk, wc, sil_pix, sil_oid


@kernel()
def texel_coords(wspan, wk, wc, rp, v, first, ma, mb, entry, texsize, rects):  # pragma: no cover - compiled
    """The textured winners (indices into the winners) and their atlas coordinates (x, y) float32:
    s = (a'/c + 1)/2 times the texels across, wrapped into the entry's tile, plus the tile's origin."""
    n = 0
    for w in range(len(wspan)):
        if entry[rp[wspan[w]]] >= 0:
            n += 1
    t = np.empty(n, np.int64)
    tx = np.empty(n, np.float32)
    ty = np.empty(n, np.float32)
    one = f32(1.0)
    j = 0
    for w in range(len(wspan)):
        s = wspan[w]
        i = rp[s]
        e = entry[i]
        if e < 0:
            continue
        # a' = a'_0 + a'_u k, b' likewise, with a'_0 = ma0 lo + ma1 v + ma2 at the span's first pixel
        a0 = f32(ma[i, 0] * first[s] + ma[i, 1] * v[s] + ma[i, 2])
        b0 = f32(mb[i, 0] * first[s] + mb[i, 1] * v[s] + mb[i, 2])
        ap = a0 + f32(ma[i, 0]) * wk[w]
        bp = b0 + f32(mb[i, 0]) * wk[w]
        hx, hy = f32(0.5 * texsize[i, 0]), f32(0.5 * texsize[i, 1])
        ex, ey, ew, eh = f32(rects[e, 0]), f32(rects[e, 1]), f32(rects[e, 2]), f32(rects[e, 3])
        x = (ap / wc[w] + one) * hx
        y = (bp / wc[w] + one) * hy
        x -= f32(np.floor(x / ew)) * ew
        y -= f32(np.floor(y / eh)) * eh
        t[j], tx[j], ty[j] = w, x + ex, y + ey
        j += 1
    return t, tx, ty


@kernel()
def shade_winners(img, ids, em, wpix, wspan, rp, obj_id, emissive, color, albedo):  # pragma: no cover - compiled
    """Write each winner's object id, lamp flag and colour = shaded colour x albedo (float32, truncated), in
    order (the last of equal fragments wins); ``img`` (H W, 3), ``ids`` and ``em`` flat (empty to skip)."""
    has_ids, has_em = ids.size > 0, em.size > 0
    for w in range(len(wpix)):
        p, i = wpix[w], rp[wspan[w]]
        if has_ids:
            ids[p] = obj_id[i]
        if has_em:
            em[p] = f32(emissive[i])
        a = albedo[w]
        for ch in range(3):
            img[p, ch] = np.uint8(color[i, ch] * a)
