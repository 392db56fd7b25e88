"""Row spans of patches and the coverage of their end pixels (horizontal anti-aliasing).

Along an image row v the inside of a patch is one interval [lo, hi] of real u (see ``fragments.py``); the
rasteriser fills the pixel centres inside it. Filling centres alone puts every vertical edge on a whole
pixel, in both images of the stereo pair, so that the disparity of an object's outline is rounded to whole
pixels whatever its depth. ``smooth_edges`` restores the box filter at the two ends of each span: the pixel
the edge crosses shows the patch and what lies behind it in proportion to the area each covers (the
neighbour across the edge stands for what lies behind). Vertical coverage (top and bottom rows) is not
modelled: it does not move disparities.

The per-row work is compiled (numba, ``cache=True``): loops in float64 with the operations in the order the
vectorised numpy version used, so that the images are the same bit for bit.
"""

from __future__ import annotations

import numpy as np

from percept.compiled import kernel, optional

EDGE_TOL = 2e-5
"""Relative 1/Z tolerance that tells "this pixel shows the patch" (float32 rounding is about 1e-7) from "it
shows a surface behind it" (a tail light 1 cm in front of a car at 260 m is 4e-5 nearer)."""


def span_bounds(p, idx: np.ndarray) -> tuple[np.ndarray, ...]:
    """Every box row of the patches ``idx`` (``PreparedPatches``, none crossing the near plane), in order:
    patch, row v, the real interval [lo, hi] of u inside the outline (lo > hi when the row has none), and the
    first and last pixel centre k with lo <= k <= hi, clipped to the patch's box (first > last: none)."""
    n = int((p.y1[idx] - p.y0[idx]).sum())
    rp, v, first, last = (np.empty(n, np.int64) for _ in range(4))
    lo, hi = np.empty(n), np.empty(n)
    _bounds(idx, p.x0, p.x1, p.y0, p.y1, p.ma, p.mb, p.mc, p.ellipse, rp, v, lo, hi, first, last)
    return rp, v, lo, hi, first, last


@kernel()
def _bounds(idx, x0, x1, y0, y1, ma, mb, mc, ellipse, rp, v, lo, hi, first, last):  # pragma: no cover - compiled
    r = 0
    for i in idx:
        for row in range(y0[i], y1[i]):
            rp[r], v[r] = i, row
            vv = np.float64(row)
            if not ellipse[i]:
                # quad: the half-planes c ± a' >= 0, c ± b' >= 0 are alpha u + delta >= 0 on row v; each bounds u
                lq, hq = -np.inf, np.inf
                for k in range(4):
                    m = ma if k < 2 else mb
                    if k % 2 == 0:
                        alpha, d1, d2 = mc[i, 0] + m[i, 0], mc[i, 1] + m[i, 1], mc[i, 2] + m[i, 2]
                    else:
                        alpha, d1, d2 = mc[i, 0] - m[i, 0], mc[i, 1] - m[i, 1], mc[i, 2] - m[i, 2]
                    delta = d1 * vv + d2
                    x = -delta / alpha
                    if alpha > 0:
                        lq = max(lq, x)
                    elif alpha < 0:
                        hq = min(hq, x)
                    elif delta < 0:
                        # alpha = 0: the whole row is outside (delta < 0) or inside
                        hq = -np.inf
                lo[r], hi[r] = lq, hq
            else:
                # ellipse: (A1 u + A0)^2 + (B1 u + B0)^2 - (C1 u + C0)^2 <= 0, i.e. q2 u^2 + q1 u + q0 <= 0
                ga, gb, gc = ma[i, 0], mb[i, 0], mc[i, 0]
                fa, fb, fc = ma[i, 1] * vv + ma[i, 2], mb[i, 1] * vv + mb[i, 2], mc[i, 1] * vv + mc[i, 2]
                q2 = (ga * ga + gb * gb) - gc * gc
                q1 = (2.0 * (ga * fa) + 2.0 * (gb * fb)) - 2.0 * (gc * fc)
                q0 = (fa * fa + fb * fb) - fc * fc
                disc = q1 * q1 - 4.0 * q2 * q0
                root = np.sqrt(max(disc, 0.0))
                if disc < 0 or not q2 > 0:
                    lo[r], hi[r] = np.inf, -np.inf
                else:
                    lo[r], hi[r] = (-q1 - root) / (2.0 * q2), (-q1 + root) / (2.0 * q2)
            # the pixel centres inside, clipped to the box
            first[r] = np.int64(min(max(np.ceil(lo[r]), x0[i]), x1[i]))
            last[r] = np.int64(min(max(np.floor(hi[r]), x0[i] - 1), x1[i] - 1))
            r += 1


def smooth_edges(target, p, rp: np.ndarray, v: np.ndarray, lo: np.ndarray, hi: np.ndarray, lo_px: np.ndarray,
                 hi_px: np.ndarray) -> None:
    """Blend the pixel each span's left and right edge crosses, by its coverage, in ``target.image`` (and its
    emission map).

    Left edge at lo, first inside centre j = ceil(lo), f = j - lo in [0, 1): pixel j covers [j - 1/2, j + 1/2].
    When f >= 1/2 pixel j is wholly inside and the outside neighbour n = j - 1 is covered by f - 1/2; when
    f < 1/2 pixel j is covered by 1/2 + f and shows the background for the rest. (The right edge mirrors it.)
    An edge is blended only where pixel j shows the patch (its 1/Z within EDGE_TOL of the patch's) and the
    neighbour shows something behind the patch's plane; an occluded edge belongs to its occluder. ``lo_px``,
    ``hi_px``: the spans' first and last pixel centres (``span_bounds``), as the rasteriser filled them."""
    _smooth(target.image.reshape(-1, 3), target.inv_depth.reshape(-1),
            optional(target.emission, np.float32).reshape(-1), target.inv_depth.shape[1], p.mc, rp, v, lo, hi, lo_px,
            hi_px)


@kernel()
def _smooth(img, inv, em, W, mc, rp, v, lo, hi, lo_px, hi_px):  # pragma: no cover - compiled
    n = len(rp)
    tgt = np.empty(2 * n, np.int64)
    src = np.empty(2 * n, np.int64)
    alpha = np.empty(2 * n)
    m = 0
    # the left edges of every span, then the right ones
    for side in range(2):
        for r in range(n):
            if lo_px[r] > hi_px[r] or not np.isfinite(lo[r]) or not np.isfinite(hi[r]):
                continue
            if side == 0:
                j, f, nb = lo_px[r], lo_px[r] - lo[r], lo_px[r] - 1
            else:
                j, f, nb = hi_px[r], hi[r] - hi_px[r], hi_px[r] + 1
            if not (f >= 0 and f < 1 and nb >= 0 and nb < W):
                continue
            i, vv = rp[r], v[r]
            # 1/Z of the patch's plane at both pixels: c = mc0 u + mc1 v + mc2
            cj = mc[i, 0] * j + mc[i, 1] * vv + mc[i, 2]
            cn = mc[i, 0] * nb + mc[i, 1] * vv + mc[i, 2]
            pj, pn = vv * W + j, vv * W + nb
            if not (abs(inv[pj] - cj) <= EDGE_TOL * cj and inv[pn] < cn * (1.0 - EDGE_TOL)):
                continue
            # f >= 1/2: the neighbour takes (f - 1/2) of pixel j's colour; else pixel j takes (1/2 - f) of the
            # neighbour's
            if f >= 0.5:
                tgt[m], src[m] = pn, pj
            else:
                tgt[m], src[m] = pj, pn
            alpha[m] = abs(f - 0.5)
            m += 1
    # colour = (1 - a) * own + a * other, all from the unblended image, then written in order
    mixed = np.empty((m, 3), np.uint8)
    for k in range(m):
        a = alpha[k]
        for ch in range(3):
            mixed[k, ch] = np.uint8(np.rint((1.0 - a) * img[tgt[k], ch] + a * img[src[k], ch]))
    if em.size > 0:
        blend = np.empty(m, np.float32)
        for k in range(m):
            blend[k] = (1.0 - alpha[k]) * em[tgt[k]] + alpha[k] * em[src[k]]
        for k in range(m):
            em[tgt[k]] = blend[k]
    # channel by channel: a row assigned as an array (img[t] = mixed[k]) is far slower in numba
    for k in range(m):
        for ch in range(3):
            img[tgt[k], ch] = mixed[k, ch]
