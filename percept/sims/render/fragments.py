"""Pixel kernels of the rasteriser: exact row spans, large patches one by one, small ones all at once.

Every patch gives, per pixel centre (u, v), three affine functions

    a' = ma·(u, v, 1),  b' = mb·(u, v, 1),  c = mc·(u, v, 1) = 1/Z

and the pixel is inside the outline when max(|a'|, |b'|) <= c (quad) or a'^2 + b'^2 <= c^2 (ellipse).
Along an image row these are linear in u, so the inside pixels of a row form one span [lo, hi]: the
quad's four half-planes c ± a' >= 0, c ± b' >= 0 bound it, the ellipse's quadratic has it between its
roots. A pixel is drawn when it is inside and nearer than the z-buffer (c > 1/Z_buf); texture
coordinates are s = (a'/c + 1)/2 and t = (b'/c + 1)/2. Patches cut by the near plane are tested per
pixel instead (with c < 1/near).
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from .spans import pixel_spans, smooth_edges, span_bounds
from .textures import TextureAtlas

BIG_PX = 1500
"""Patches covering more than this [px] (estimated) are rasterised one by one with OpenCV texture warps;
the others all at once as fragments (one per covered pixel) with vectorised texture lookups."""
NEAR_M = 0.3
"""Near clipping distance of every camera [m] (re-exported by raster, which imports this module)."""
INV_NEAR = 1.0 / NEAR_M
_ALBEDO = (np.arange(256, dtype=np.float32) * np.float32(1.0 / 255.0)).reshape(256, 1, 1)
"""Texel value / 255, the colour map of a patch's albedo when multiplied by its colour."""


@dataclass
class PreparedPatches:
    """Patches that survived culling, in one camera. x0, x1, y0, y1: (P,) pixel box, x1 and y1 exclusive;
    ma, mb, mc: (P, 3) affine rows (see module doc); ellipse, crossing (of the near plane): (P,) bool;
    zmin: (P,) nearest depth [m]; area: (P,) projected area [px] (NaN when crossing); obj_id: (P,);
    color: (P, 3) float32 shaded BGR; entry: (P,) atlas entry or -1; texsize: (P, 2) texels across the
    patch along e1, e2 at that entry; emissive: (P,) bool, a lamp (its pixels are marked in the target's
    emission map, for the night's glow)."""

    x0: np.ndarray
    x1: np.ndarray
    y0: np.ndarray
    y1: np.ndarray
    ma: np.ndarray
    mb: np.ndarray
    mc: np.ndarray
    ellipse: np.ndarray
    crossing: np.ndarray
    zmin: np.ndarray
    area: np.ndarray
    obj_id: np.ndarray
    color: np.ndarray
    entry: np.ndarray
    texsize: np.ndarray
    emissive: np.ndarray


def rasterize_prepared(target, p: PreparedPatches, atlas: TextureAtlas, silhouettes: bool,
                       antialias: bool = True) -> None:
    """Draw prepared patches into ``target`` (z-tested against ``target.inv_depth``); ``antialias``: blend the
    pixels vertical edges cross by their coverage (``spans.smooth_edges``)."""
    with np.errstate(invalid="ignore"):
        big = p.crossing | ~(p.area <= BIG_PX)
    sil: dict[int, list[np.ndarray]] | None = target.silhouettes if silhouettes else None
    # nearest first, so that hidden pixels are rejected by the z-test early
    order = np.flatnonzero(big)
    order = order[np.argsort(p.zmin[order], kind="stable")]
    small = np.flatnonzero(~big)
    # row spans of every patch in front of the near plane: the large ones first, in drawing order
    front = order[~p.crossing[order]]
    rp, v, lo, hi = span_bounds(p, np.concatenate([front, small]))
    first, last = pixel_spans(p, rp, lo, hi)
    nbig = int((p.y1[front] - p.y0[front]).sum())
    _big_patches(target, p, atlas, order, front, first[:nbig], last[:nbig], sil)
    if len(small):
        frags = _small_patches(target.inv_depth, p, rp[nbig:], v[nbig:], first[nbig:], last[nbig:], sil)
        if frags is not None:
            _shade(target, p, atlas, *frags)
    if antialias:
        smooth_edges(target, p, rp, v, lo, hi, first, last)
    # Z = 1 / c wherever a patch won the z-test
    if target.depth is not None:
        np.divide(np.float32(1.0), target.inv_depth, out=target.depth, where=target.inv_depth != target.base_inv_depth)


_GIDX: dict[tuple, np.ndarray] = {}


def _pixel_index(shape: tuple) -> np.ndarray:
    """(H, W) int32 array of flat pixel indices row * W + col (cached, read-only)."""
    g = _GIDX.get(shape)
    if g is None:
        g = np.arange(shape[0] * shape[1], dtype=np.int32).reshape(shape)
        g.flags.writeable = False
        _GIDX[shape] = g
    return g


def _texture_maps(p: PreparedPatches, atlas: TextureAtlas, order: np.ndarray) -> list:
    """Per patch in ``order``: None, or (tiled texture, 3x3 map from box pixel to its texel)."""
    out: list = [None] * len(order)
    tex = np.flatnonzero(p.entry[order] >= 0)
    if not len(tex):
        return out
    i = order[tex]
    # (s, t, 1)/Z = (m0, m1, m2)·(u, v, 1) with m0 = (a' + c)/2, m1 = (b' + c)/2, m2 = c
    M = np.stack([(p.ma[i] + p.mc[i]) / 2, (p.mb[i] + p.mc[i]) / 2, p.mc[i]], axis=1)
    # texel (after the one-texel pad) of box pixel (x, y): diag(Ts, Tt, 1) M (x + x0, y + y0, 1) + (1, 1)
    S = np.zeros((len(i), 3, 3))
    S[:, 0, 0], S[:, 1, 1], S[:, 2, 2] = p.texsize[i, 0], p.texsize[i, 1], 1.0
    S[:, 0, 2] = S[:, 1, 2] = 1.0
    Tb = np.zeros((len(i), 3, 3))
    Tb[:, 0, 0] = Tb[:, 1, 1] = Tb[:, 2, 2] = 1.0
    Tb[:, 0, 2], Tb[:, 1, 2] = p.x0[i], p.y0[i]
    maps = S @ M @ Tb
    rect = atlas.rects[p.entry[i]]
    reps = np.ceil(p.texsize[i] / rect[:, 2:4] - 1e-6).astype(int)
    for k, j in enumerate(tex.tolist()):
        out[j] = (atlas.tiled(int(p.entry[i[k]]), int(reps[k, 0]), int(reps[k, 1])), maps[k])
    return out


def _big_patches(target, p: PreparedPatches, atlas: TextureAtlas, order: np.ndarray, front: np.ndarray,
                 los: np.ndarray, his: np.ndarray, sil) -> None:
    """Patches one by one over their bounding box, written at once (textures warped by OpenCV); ``front``:
    those of them not crossing the near plane, whose row spans are ``los``, ``his`` (in that order)."""
    if not len(order):
        return
    wbuf, ids = target.inv_depth, target.ids
    # one 3-byte item per pixel, so that masked copies take a 2-D mask
    image = target.image.view(np.dtype("V3"))[..., 0]
    gidx = _pixel_index(wbuf.shape)
    us = np.arange(wbuf.shape[1], dtype=np.float32)
    vs = np.arange(wbuf.shape[0], dtype=np.float32)
    cols = np.arange(wbuf.shape[1])
    maps = _texture_maps(p, atlas, order)
    first = dict(zip(front.tolist(), (np.cumsum(p.y1[front] - p.y0[front]) - (p.y1[front] - p.y0[front])).tolist()))
    rows = zip(order.tolist(), p.x0[order].tolist(), p.x1[order].tolist(), p.y0[order].tolist(), p.y1[order].tolist(),
               p.ma[order].tolist(), p.mb[order].tolist(), p.mc[order].tolist(), p.color[order].tolist(), maps)
    for i, x0, x1, y0, y1, ma, mb, mc, color, tmap in rows:
        u, v = us[x0:x1], vs[y0:y1]
        # c(u, v) = 1/Z = mc0 u + mc1 v + mc2, as a row plus a column
        c = (np.float32(mc[0]) * u)[None, :] + (np.float32(mc[1]) * v + np.float32(mc[2]))[:, None]
        r = first.get(i)
        if r is not None:
            lo, hi = los[r:r + y1 - y0, None], his[r:r + y1 - y0, None]
            inside = (cols[None, x0:x1] >= lo) & (cols[None, x0:x1] <= hi)
        else:
            # crossing the near plane: the exact test per pixel, with c < 1/near
            ap = (np.float32(ma[0]) * u)[None, :] + (np.float32(ma[1]) * v + np.float32(ma[2]))[:, None]
            bp = (np.float32(mb[0]) * u)[None, :] + (np.float32(mb[1]) * v + np.float32(mb[2]))[:, None]
            if p.ellipse[i]:
                inside = ap * ap + bp * bp <= c * c
            else:
                inside = np.maximum(np.abs(ap), np.abs(bp)) <= c
            inside &= (c < INV_NEAR) & (c > 0)
        oid = int(p.obj_id[i])
        if sil is not None and oid > 0:
            sil.setdefault(oid, []).append(gidx[y0:y1, x0:x1][inside])
        wr = wbuf[y0:y1, x0:x1]
        vis = inside & (c > wr)
        if not vis.any():
            continue
        np.copyto(wr, c, where=vis)
        if ids is not None:
            np.copyto(ids[y0:y1, x0:x1], oid, where=vis)
        if target.emission is not None:
            np.copyto(target.emission[y0:y1, x0:x1], np.float32(p.emissive[i]), where=vis)
        if tmap is None:
            col = np.asarray(color, np.float32).astype(np.uint8).view(np.dtype("V3"))[0]
        else:
            tiled, H = tmap
            alb = cv2.warpPerspective(tiled, H, (x1 - x0, y1 - y0), flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP,
                                      borderMode=cv2.BORDER_CONSTANT)
            # colour * albedo / 255, per channel, as a 256-entry colour map of the albedo
            lut = (_ALBEDO * np.asarray(color, np.float32)).astype(np.uint8)
            col = cv2.applyColorMap(alb, lut).view(np.dtype("V3"))[..., 0]
        np.copyto(image[y0:y1, x0:x1], col, where=vis)


def _small_patches(wbuf: np.ndarray, p: PreparedPatches, rp, v, lo, hi, sil) -> tuple | None:
    """All small patches at once, one fragment per inside pixel of their row spans (patch rp, row v, columns
    lo..hi); returns the winners (pix, patch, textured subset, its a', b', c)."""
    W = wbuf.shape[1]
    n = hi - lo + 1
    keep = np.flatnonzero(n > 0)
    if not len(keep):
        return None
    rp, v, lo, n = rp[keep], v[keep], lo[keep], n[keep]
    # fragments: span s covers pixels lo_s .. lo_s + n_s - 1 of row v_s; k is the offset along the span
    sid = np.repeat(np.arange(len(rp), dtype=np.int32), n)
    k = (np.arange(len(sid), dtype=np.int32) - np.repeat((np.cumsum(n) - n).astype(np.int32), n)).astype(np.float32)
    pix = np.repeat((v * W + lo).astype(np.int32), n) + k.astype(np.int32)
    mc = np.take(p.mc, rp, axis=0)
    # c at the span's first pixel plus its slope along the row
    c0 = (mc[:, 0] * lo + mc[:, 1] * v + mc[:, 2]).astype(np.float32)
    c = np.repeat(c0, n) + np.repeat(mc[:, 0].astype(np.float32), n) * k
    if sil is not None:
        oid = p.obj_id[rp]
        objs = np.unique(oid[oid > 0])
        if len(objs):
            foid = np.repeat(oid, n)
            on = np.flatnonzero(foid > 0)
            # group the fragments by object with one stable sort (order within an object is kept)
            order = np.argsort(foid[on], kind="stable")
            opix, foid = pix[on][order], foid[on][order]
            ids, starts = np.unique(foid, return_index=True)
            for o, px in zip(ids.tolist(), np.split(opix, starts[1:])):
                sil.setdefault(o, []).append(px)
    # z-test against the buffer, then among the batch: the largest 1/Z per pixel wins (fragments with equal
    # 1/Z at a pixel are all kept; the last one written wins, the same in every buffer)
    wflat = wbuf.reshape(-1)
    np.maximum.at(wflat, pix, c)
    win = np.flatnonzero(c == wflat[pix])
    pix, sid, k, c = pix[win], sid[win], k[win], c[win]
    pi = rp[sid]
    ap = bp = None
    t = np.flatnonzero(p.entry[pi] >= 0)
    if len(t):
        # a', b' of the textured winners: value at the span start plus slope times offset, per span:
        # (a'_0, a'_u, b'_0, b'_u) with a'_0 = ma0 lo + ma1 v + ma2, a'_u = ma0
        ma, mb = np.take(p.ma, rp, axis=0), np.take(p.mb, rp, axis=0)
        ab = np.column_stack([ma[:, 0] * lo + ma[:, 1] * v + ma[:, 2], ma[:, 0],
                              mb[:, 0] * lo + mb[:, 1] * v + mb[:, 2], mb[:, 0]]).astype(np.float32)
        f = np.take(ab, sid[t], axis=0)
        kt = k[t]
        ap = f[:, 0] + f[:, 1] * kt
        bp = f[:, 2] + f[:, 3] * kt
    return pix, pi.astype(np.int32), t, ap, bp, c


def _shade(target, p: PreparedPatches, atlas: TextureAtlas, pix, pi, t, ap, bp, c) -> None:
    """Write ids and colour of the winning fragments; ``t`` indexes the textured ones, whose a', b'
    are ``ap``, ``bp``."""
    if target.ids is not None:
        target.ids.reshape(-1)[pix] = p.obj_id[pi]
    if target.emission is not None:
        target.emission.reshape(-1)[pix] = p.emissive[pi]
    albedo = np.ones(len(pix), np.float32)
    if len(t):
        # per textured patch: half the texels across (e1, e2), the atlas entry's interior x0, y0, w, h
        tex = p.entry >= 0
        table = np.zeros((len(p.x0), 6), np.float32)
        table[tex, 0:2] = 0.5 * p.texsize[tex]
        table[tex, 2:6] = atlas.rects[p.entry[tex]]
        ft = np.take(table, pi[t], axis=0)
        ct = c[t]
        # texel coordinates: s = (a'/c + 1)/2 times the texels across, wrapped into the entry's tile
        tx = (ap / ct + 1.0) * ft[:, 0]
        ty = (bp / ct + 1.0) * ft[:, 1]
        tx -= np.floor(tx / ft[:, 4]) * ft[:, 4]
        ty -= np.floor(ty / ft[:, 5]) * ft[:, 5]
        albedo[t] = _sample(atlas.image, tx + ft[:, 2], ty + ft[:, 3]) * np.float32(1.0 / 255.0)
    # colour = shaded patch colour * albedo
    col = np.take(p.color, pi, axis=0) * albedo[:, None]
    # one 3-byte item per pixel: a 1-D scatter instead of a row-wise one
    target.image.reshape(-1).view(np.dtype("V3"))[pix] = col.astype(np.uint8).reshape(-1).view(np.dtype("V3"))


def _sample(image: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Bilinear samples of ``image`` at (x, y) (N,), via cv2.remap on maps folded into rows of 1024."""
    n = len(x)
    m = -(-n // 1024) * 1024
    mx = np.zeros(m, np.float32)
    my = np.zeros(m, np.float32)
    mx[:n], my[:n] = x, y
    out = cv2.remap(image, mx.reshape(-1, 1024), my.reshape(-1, 1024), cv2.INTER_LINEAR,
                    borderMode=cv2.BORDER_REPLICATE)
    return out.reshape(-1)[:n]
