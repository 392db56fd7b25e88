"""Row spans of patches and the coverage of their end pixels (horizontal anti-aliasing).

Along an image row v the inside of a patch is one interval [lo, hi] of real u (see ``fragments.py``); the
rasteriser fills the pixel centres inside it. Filling centres alone puts every vertical edge on a whole
pixel, in both images of the stereo pair, so that the disparity of an object's outline is rounded to whole
pixels whatever its depth. ``smooth_edges`` restores the box filter at the two ends of each span: the pixel
the edge crosses shows the patch and what lies behind it in proportion to the area each covers (the
neighbour across the edge stands for what lies behind). Vertical coverage (top and bottom rows) is not
modelled: it does not move disparities.
"""

from __future__ import annotations

import numpy as np

EDGE_TOL = 2e-5
"""Relative 1/Z tolerance that tells "this pixel shows the patch" (float32 rounding is about 1e-7) from "it
shows a surface behind it" (a tail light 1 cm in front of a car at 260 m is 4e-5 nearer)."""


def span_bounds(p, idx: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Every box row of the patches ``idx`` (``PreparedPatches``, none crossing the near plane), in order:
    patch, row v, and the real interval [lo, hi] of u inside the outline (lo > hi when the row has none)."""
    h = p.y1[idx] - p.y0[idx]
    rp = np.repeat(idx, h)
    v = (np.arange(len(rp)) - np.repeat(np.cumsum(h) - h, h) + np.repeat(p.y0[idx], h)).astype(np.float64)
    lo = np.empty(len(rp))
    hi = np.empty(len(rp))
    ell = p.ellipse[rp]
    q, e = np.flatnonzero(~ell), np.flatnonzero(ell)
    with np.errstate(divide="ignore", invalid="ignore"):
        if len(q):
            # quad: the half-planes c ± a' >= 0, c ± b' >= 0 are alpha u + delta >= 0 on row v; each bounds u
            half = np.concatenate([p.mc + p.ma, p.mc - p.ma, p.mc + p.mb, p.mc - p.mb], axis=1)  # (P, 12)
            m = np.take(half, rp[q], axis=0)
            vq = v[q]
            lq = np.full(len(q), -np.inf)
            hq = np.full(len(q), np.inf)
            for k in range(0, 12, 3):
                alpha, delta = m[:, k], m[:, k + 1] * vq + m[:, k + 2]
                x = -delta / alpha
                lq = np.maximum(lq, np.where(alpha > 0, x, -np.inf))
                # alpha = 0: the whole row is inside (delta >= 0) or outside
                hq = np.minimum(hq, np.where(alpha < 0, x, np.where((alpha == 0) & (delta < 0), -np.inf, np.inf)))
            lo[q], hi[q] = lq, hq
        if len(e):
            # ellipse: (A1 u + A0)^2 + (B1 u + B0)^2 - (C1 u + C0)^2 <= 0, i.e. q2 u^2 + q1 u + q0 <= 0
            m = np.take(np.stack([p.ma, p.mb, p.mc], axis=1), rp[e], axis=0)  # (n, 3, 3)
            g = m[:, :, 0]
            f = m[:, :, 1] * v[e, None] + m[:, :, 2]
            sign = np.array([1.0, 1.0, -1.0])
            q2 = (g * g) @ sign
            q1 = 2 * (g * f) @ sign
            q0 = (f * f) @ sign
            disc = q1 * q1 - 4 * q2 * q0
            root = np.sqrt(np.maximum(disc, 0))
            none = (disc < 0) | ~(q2 > 0)
            lo[e] = np.where(none, np.inf, (-q1 - root) / (2 * q2))
            hi[e] = np.where(none, -np.inf, (-q1 + root) / (2 * q2))
    return rp, v.astype(np.int64), lo, hi


def pixel_spans(p, rp: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The first and last pixel centre k with lo <= k <= hi, clipped to the patch's box (first > last: none)."""
    x0, x1 = p.x0[rp], p.x1[rp]
    first = np.clip(np.ceil(lo), x0, x1).astype(np.int64)
    last = np.clip(np.floor(hi), x0 - 1, x1 - 1).astype(np.int64)
    return first, last


def smooth_edges(target, p, rp: np.ndarray, v: np.ndarray, lo: np.ndarray, hi: np.ndarray, lo_px: np.ndarray,
                 hi_px: np.ndarray) -> None:
    """Blend the pixel each span's left and right edge crosses, by its coverage, in ``target.image`` (and its
    emission map).

    Left edge at lo, first inside centre j = ceil(lo), f = j - lo in [0, 1): pixel j covers [j - 1/2, j + 1/2].
    When f >= 1/2 pixel j is wholly inside and the outside neighbour n = j - 1 is covered by f - 1/2; when
    f < 1/2 pixel j is covered by 1/2 + f and shows the background for the rest. (The right edge mirrors it.)
    An edge is blended only where pixel j shows the patch (its 1/Z within EDGE_TOL of the patch's) and the
    neighbour shows something behind the patch's plane; an occluded edge belongs to its occluder. ``lo_px``,
    ``hi_px``: the spans' first and last pixel centres (``pixel_spans``), as the rasteriser filled them."""
    H, W = target.inv_depth.shape
    ok = (lo_px <= hi_px) & np.isfinite(lo) & np.isfinite(hi)
    img = target.image
    inv = target.inv_depth.reshape(-1)
    mc = np.take(p.mc, rp, axis=0)
    targets, sources, alphas = [], [], []
    for j, f, step in ((lo_px, lo_px - lo, -1), (hi_px, hi - hi_px, 1)):
        n = j + step
        s = np.flatnonzero(ok & (f >= 0) & (f < 1) & (n >= 0) & (n < W))
        if not len(s):
            continue
        js, ns, vs, fs, m = j[s], n[s], v[s], f[s], mc[s]
        # 1/Z of the patch's plane at both pixels: c = mc0 u + mc1 v + mc2
        cj = m[:, 0] * js + m[:, 1] * vs + m[:, 2]
        cn = m[:, 0] * ns + m[:, 1] * vs + m[:, 2]
        pj, pn = vs * W + js, vs * W + ns
        keep = (np.abs(inv[pj] - cj) <= EDGE_TOL * cj) & (inv[pn] < cn * (1.0 - EDGE_TOL))
        pj, pn, fs = pj[keep], pn[keep], fs[keep]
        # f >= 1/2: the neighbour takes (f - 1/2) of pixel j's colour; else pixel j takes (1/2 - f) of the neighbour's
        out = fs >= 0.5
        targets.append(np.where(out, pn, pj))
        sources.append(np.where(out, pj, pn))
        alphas.append(np.abs(fs - 0.5))
    if not targets:
        return
    t, s, a = np.concatenate(targets), np.concatenate(sources), np.concatenate(alphas)[:, None]
    tv, tu, sv, su = t // W, t % W, s // W, s % W
    # colour = (1 - a) * own + a * other, from the unblended image
    mixed = (1.0 - a) * img[tv, tu] + a * img[sv, su]
    if target.emission is not None:
        e = target.emission
        blend = (1.0 - a[:, 0]) * e[tv, tu] + a[:, 0] * e[sv, su]
        e[tv, tu] = blend
    img[tv, tu] = np.rint(mixed).astype(np.uint8)
