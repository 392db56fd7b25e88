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

from percept.compiled import optional

from .pixels import big_patches, clear_boxes, put_albedo, zbuffer_depth
from .small_patches import shade_winners, small_fragments, texel_coords
from .spans import smooth_edges, span_bounds
from .textures import TextureAtlas

BIG_PX = 1500
"""Patches covering more than this [px] (estimated) are rasterised one by one with OpenCV texture warps;
the others all at once as fragments (one per covered pixel) with vectorised texture lookups."""
NEAR_M = 0.3
"""Near clipping distance of every camera [m] (re-exported by raster, which imports this module)."""
INV_NEAR = 1.0 / NEAR_M
_ALBEDO = (np.arange(256, dtype=np.float32) * np.float32(1.0 / 255.0)).reshape(256, 1, 1)
"""Texel value / 255, the colour map of a patch's albedo when multiplied by its colour."""


class WinnerMap:
    """A camera's (H, W) int32 scratch map for ``big_patches`` (which patch holds each pixel), all -1 between
    frames: lent to one rasterisation at a time and cleared over the boxes it drew on, so that no frame fills a
    fresh one; filled again if a rasterisation did not give it back (interrupted)."""

    def __init__(self, shape: tuple[int, int]):
        self.map = np.full(shape, -1, np.int32)
        self._lent = False

    def take(self) -> np.ndarray:
        if self._lent:
            self.map.fill(-1)
        self._lent = True
        return self.map

    def give_back(self) -> None:
        self._lent = False


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
    rp, v, lo, hi, first, last = span_bounds(p, np.concatenate([front, small]))
    nbig = int((p.y1[front] - p.y0[front]).sum())
    _big_patches(target, p, atlas, order, front, first[:nbig], last[:nbig], sil)
    if len(small):
        _small_patches(target, p, atlas, rp[nbig:], v[nbig:], first[nbig:], last[nbig:], sil)
    if antialias:
        smooth_edges(target, p, rp, v, lo, hi, first, last)
    if target.depth is not None:
        # Z = 1 / c wherever a patch won the z-test, what the depth held before elsewhere
        target.depth = zbuffer_depth(target.inv_depth, target.base_inv_depth, target.depth)


def _add_silhouettes(sil: dict[int, list[np.ndarray]] | None, pix: np.ndarray, oid: np.ndarray) -> None:
    """Append flat pixel indices ``pix`` to the silhouette of their objects ``oid`` (order within an object kept)."""
    if sil is None or not len(pix):
        return
    order = np.argsort(oid, kind="stable")
    ids, starts = np.unique(oid[order], return_index=True)
    for o, px in zip(ids.tolist(), np.split(pix[order], starts[1:])):
        sil.setdefault(o, []).append(px)


def _texture_maps(p: PreparedPatches, atlas: TextureAtlas, idx: np.ndarray) -> list:
    """Per textured patch ``idx``: (tiled texture, 3x3 map from box pixel to its texel)."""
    # (s, t, 1)/Z = (m0, m1, m2)·(u, v, 1) with m0 = (a' + c)/2, m1 = (b' + c)/2, m2 = c
    M = np.stack([(p.ma[idx] + p.mc[idx]) / 2, (p.mb[idx] + p.mc[idx]) / 2, p.mc[idx]], axis=1)
    # texel (after the one-texel pad) of box pixel (x, y): diag(Ts, Tt, 1) M (x + x0, y + y0, 1) + (1, 1)
    S = np.zeros((len(idx), 3, 3))
    S[:, 0, 0], S[:, 1, 1], S[:, 2, 2] = p.texsize[idx, 0], p.texsize[idx, 1], 1.0
    S[:, 0, 2] = S[:, 1, 2] = 1.0
    Tb = np.zeros((len(idx), 3, 3))
    Tb[:, 0, 0] = Tb[:, 1, 1] = Tb[:, 2, 2] = 1.0
    Tb[:, 0, 2], Tb[:, 1, 2] = p.x0[idx], p.y0[idx]
    maps = S @ M @ Tb
    rect = atlas.rects[p.entry[idx]]
    reps = np.ceil(p.texsize[idx] / rect[:, 2:4] - 1e-6).astype(int)
    return [(atlas.tiled(int(p.entry[i]), int(reps[k, 0]), int(reps[k, 1])), maps[k]) for k, i in enumerate(idx)]


def _big_patches(target, p: PreparedPatches, atlas: TextureAtlas, order: np.ndarray, front: np.ndarray,
                 los: np.ndarray, his: np.ndarray, sil) -> None:
    """Patches one by one over their bounding box (``pixels.big_patches``); ``front``: those of them not crossing
    the near plane, whose row spans are ``los``, ``his`` (in that order). A textured patch's colour is warped by
    OpenCV afterwards, over the pixels it still holds."""
    if not len(order):
        return
    span_row = np.full(len(p.x0), -1, np.int64)
    h = p.y1[front] - p.y0[front]
    span_row[front] = np.cumsum(h) - h
    textured = p.entry >= 0
    winner = target.winner.take() if target.winner is not None else np.full(target.inv_depth.shape, -1, np.int32)
    held, ends, sil_pix, sil_oid = big_patches(
        target.inv_depth, optional(target.ids, np.int32), optional(target.emission, np.float32), target.image,
        winner, order, p.x0, p.x1, p.y0, p.y1, p.ma, p.mb, p.mc, p.ellipse, span_row, los, his, p.obj_id, p.emissive,
        p.color, textured, sil is not None, np.float32(INV_NEAR))
    _add_silhouettes(sil, sil_pix, sil_oid)
    ks = np.flatnonzero(textured[order] & (held > 0))
    if len(ks):
        _put_textures(target, p, atlas, order, ks, ends, winner)
    if target.winner is not None:
        clear_boxes(winner, order, p.x0, p.x1, p.y0, ends)
        target.winner.give_back()


def _put_textures(target, p: PreparedPatches, atlas: TextureAtlas, order: np.ndarray, ks: np.ndarray,
                  ends: np.ndarray, winner: np.ndarray) -> None:
    """The textured big patches ``order[ks]`` warped by OpenCV over their boxes down to ``ends`` and written where
    ``winner`` still names them."""
    idx = order[ks]
    x0s, x1s, y0s, y_ends = p.x0[idx].tolist(), p.x1[idx].tolist(), p.y0[idx].tolist(), ends[ks].tolist()
    # colour * albedo / 255, per channel, as a 256-entry colour map of the albedo
    luts = (_ALBEDO * p.color[idx][:, None, None, :]).astype(np.uint8)
    for j, (tiled, H) in enumerate(_texture_maps(p, atlas, idx)):
        # the warp stops after the last row in which the patch won a pixel: OpenCV warps each row on its own, so the
        # rows above come out the same (a box cut on the right would not: its last columns leave the vector loop
        # differently)
        alb = cv2.warpPerspective(tiled, H, (x1s[j] - x0s[j], y_ends[j] - y0s[j]),
                                  flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP, borderMode=cv2.BORDER_CONSTANT)
        put_albedo(target.image, alb, luts[j], winner, int(ks[j]), x0s[j], y0s[j])


def _small_patches(target, p: PreparedPatches, atlas: TextureAtlas, rp, v, first, last, sil) -> None:
    """All small patches at once, one fragment per inside pixel of their row spans (patch rp, row v, columns
    first..last): the z-test (``small_patches.small_fragments``), then the winners' texels sampled by OpenCV and
    their ids, lamp flags and colours written (``small_patches.shade_winners``)."""
    W = target.inv_depth.shape[1]
    wpix, wspan, wk, wc, sil_pix, sil_oid = small_fragments(target.inv_depth.reshape(-1), W, rp, v, first, last,
                                                            p.mc, p.obj_id, sil is not None)
    _add_silhouettes(sil, sil_pix, sil_oid)
    t, tx, ty = texel_coords(wspan, wk, wc, rp, v, first, p.ma, p.mb, p.entry, p.texsize, atlas.rects)
    albedo = np.ones(len(wpix), np.float32)
    if len(t):
        albedo[t] = _sample(atlas.image, tx, ty) * np.float32(1.0 / 255.0)
    shade_winners(target.image.reshape(-1, 3), optional(target.ids, np.int32).reshape(-1),
                  optional(target.emission, np.float32).reshape(-1), wpix, wspan, rp, p.obj_id, p.emissive, p.color,
                  albedo)


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
