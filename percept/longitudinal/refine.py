"""Subpixel disparity of an obstacle: one disparity for all its pixels, by direct alignment of its left-image
patch with the right image (1-D Lucas-Kanade along the rows, Gauss-Newton with Huber weights).

For a fronto-parallel surface the right image is the left one shifted: L(u, v) = R(u - d, v). With the residual
r = L - R(u - d) and g = dR/du (u - d), one Gauss-Newton step is delta = -sum(w g r) / sum(w g^2)
(Lucas & Kanade 1981; Baker & Matthews 2004). Averaging over the hundreds of pixels of a car's back gets the
disparity to a few hundredths of a pixel, below the 0.1 px a single match achieves.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from percept.compiled import kernel, pairwise_sum


@dataclass(frozen=True)
class Refined:
    """disparity_px: the patch's disparity [px]; sigma_px: its standard error [px]; pixels: used pixels;
    converged: the last step was below the tolerance."""

    disparity_px: float
    sigma_px: float
    pixels: int
    converged: bool


def surface_mask(left: np.ndarray, right: np.ndarray, box: tuple[int, int, int, int], d0: float,
                 radius: int = 3, block: int = 5, tol_px: float = 1.0, min_contrast: float = 3.0,
                 max_cost_ratio: float = 0.5) -> np.ndarray | None:
    """Which pixels of ``box`` lie on the surface at disparity ``d0``: full-resolution block matching over the
    integer disparities within ``radius`` of d0 (box-filtered absolute differences), keeping the pixels whose
    best disparity (parabola-interpolated) is within ``tol_px`` of d0 and whose cost curve has a clear minimum
    (at least ``min_contrast`` grey levels below the mean cost, and below ``max_cost_ratio`` times it).
    (v1-v0, u1-u0) bool, or None when the box leaves the image."""
    u0, v0, u1, v1 = box
    w = right.shape[1]
    lo = int(np.floor(d0)) - radius
    # the candidates d = lo .. lo + 2 radius + 1 read the right image's columns u0 - d .. u1 - d - 1, all of which
    # must exist for the costs to be formed
    if u0 - lo - 2 * radius - 1 < 0 or lo < 1 or u1 - lo + 1 > w:
        return None
    L = left[v0:v1, u0:u1]
    costs = []
    for d in range(lo, lo + 2 * radius + 2):
        # SAD_d(u, v) = box_filter(|L(u, v) - R(u - d, v)|)
        costs.append(cv2.blur(np.abs(L - right[v0:v1, u0 - d:u1 - d]), (block, block)))
    return _clear_minimum(tuple(costs), lo, np.float64(d0), tol_px, np.float32(min_contrast),
                          np.float32(max_cost_ratio))


@kernel()
def _clear_minimum(costs, lo, d0, tol_px, min_contrast, max_cost_ratio):  # pragma: no cover - compiled
    """The mask of ``surface_mask`` from its block costs (a tuple of (h, w) float32 arrays, one per disparity from lo),
    per pixel in numpy's types: the first smallest cost's index k (kept off the ends), the parabola's offset
    (c0 - c2) / (2 max(c0 - 2 c1 + c2, 1e-6)) in float32, the best disparity lo + k + offset in float64, the mean cost
    summed in order over the disparities in float32."""
    n = len(costs)
    h, w = costs[0].shape
    out = np.empty((h, w), np.bool_)
    eps = np.float32(1e-6)
    for y in range(h):
        for x in range(w):
            k = 0
            for i in range(1, n):
                if costs[i][y, x] < costs[k][y, x]:
                    k = i
            k = min(max(k, 1), n - 2)
            c0, c1, c2 = costs[k - 1][y, x], costs[k][y, x], costs[k + 1][y, x]
            # den = c0 - 2 c1 + c2; offset = (c0 - c2) / (2 (c0 - 2 c1 + c2))
            den = (c0 - np.float32(2) * c1) + c2
            offset = (c0 - c2) / (np.float32(2) * max(den, eps)) if den > eps else np.float32(0)
            best = np.float64(lo + k) + np.float64(offset)
            total = costs[0][y, x]
            for i in range(1, n):
                total += costs[i][y, x]
            mean = total / np.float32(n)
            out[y, x] = (abs(best - d0) < tol_px and den > eps and mean - c1 > min_contrast
                         and c1 < max_cost_ratio * mean)
    return out


class PatchAligner:
    """A left-image patch prepared for alignment with the right image: the right image and its row gradient as
    the two channels of one image (one remap samples both), and the patch's pixel grid. ``refine`` may be called
    several times (other masks, other starts) on the same preparation. ``left``, ``right``: float32 grey images of
    one size; ``box``: (u0, v0, u1, v1)."""

    def __init__(self, left: np.ndarray, right: np.ndarray, box: tuple[int, int, int, int]):
        u0, v0, u1, v1 = box
        self.box, self.width = box, right.shape[1]
        self.L = left[v0:v1, u0:u1]
        gx = cv2.Sobel(right, cv2.CV_32F, 1, 0, ksize=3, scale=0.125)
        self.right_gx = cv2.merge([right, gx])
        # the pixel grid (np.mgrid's, in float32), filled from its row and column
        self.vv, self.uu = np.empty((2, v1 - v0, u1 - u0), np.float32)
        self.vv[:] = np.arange(v0, v1, dtype=np.float32)[:, None]
        self.uu[:] = np.arange(u0, u1, dtype=np.float32)

    def refine(self, mask: np.ndarray | None, d0: float, iterations: int = 10, huber: float = 6.0,
               tol: float = 1e-3) -> Refined | None:
        """Disparity [px] of the patch's pixels in ``mask`` ((v1-v0, u1-u0) bool, None = all) from ``d0``; None when
        the patch has no texture or leaves the image."""
        u0, v0, u1, v1 = self.box
        if u1 - u0 < 3 or v1 - v0 < 3 or not np.isfinite(d0):
            return None
        L, w = self.L, self.width
        keep = np.ones(L.shape, bool) if mask is None else mask[:L.shape[0], :L.shape[1]]
        d, converged, step = float(d0), False, np.inf
        first, last, huber32 = np.float32(u0), np.float32(u1 - 1), np.float32(huber)
        # (the remapped patch has the grid's shape)
        mismatch = self.uu.shape != L.shape or keep.shape != L.shape
        shifted = np.empty_like(self.uu)
        for _ in range(iterations):
            # the sampled columns u - d (float32, as remap reads them) must leave room for the cubic kernel
            d32 = np.float32(d)
            if float(first - d32) < 1 or float(last - d32) > w - 2:
                return None
            both = cv2.remap(self.right_gx, np.subtract(self.uu, d, out=shifted), self.vv, cv2.INTER_CUBIC)
            if mismatch:
                raise ValueError(f"mask {keep.shape} and box {both.shape[:2]} must match the patch {L.shape}")
            # (the kernel's float32 sums come back as Python floats)
            H, wgr, wrr = _weighted_sums(L, both, keep, huber32)
            if H < 1e-3:
                return None
            # Gauss-Newton: delta = -sum(w g r) / sum(w g^2)
            step = -wgr / H
            d += min(max(step, -1.0), 1.0)
            if abs(step) < tol:
                converged = True
                break
        n = int(keep.sum())
        # standard error of the estimate: sigma^2 = sum(w r^2) / (n - 1) / sum(w g^2)
        s2 = wrr / max(n - 1, 1) / H
        return Refined(d, float(np.sqrt(s2)), n, converged)


@kernel()
def _weighted_sums(L, both, keep, huber):  # pragma: no cover - compiled
    """sum(w g^2), sum(w g r), sum(w r^2) over the patch, float32, for the residual r = L - R and Huber weights
    w = (1 if |r| <= huber else huber / max(|r|, 1e-6)) x keep, with R, g the two channels of ``both`` (h, w, 2): the
    float32 arrays numpy makes of those products, summed as numpy sums them (``pairwise_sum``), so equal bit for bit."""
    h, w = L.shape
    n = h * w
    wgg, wgr, wrr = np.empty(n, np.float32), np.empty(n, np.float32), np.empty(n, np.float32)
    eps = np.float32(1e-6)
    for y in range(h):
        for x in range(w):
            g = both[y, x, 1]
            r = L[y, x] - both[y, x, 0]
            a = abs(r)
            wt = np.float32(1.0) if a <= huber else huber / max(a, eps)
            wt = wt * np.float32(keep[y, x])
            k = y * w + x
            wgg[k], wgr[k], wrr[k] = wt * g * g, wt * g * r, wt * r * r
    return pairwise_sum(wgg, 0, n), pairwise_sum(wgr, 0, n), pairwise_sum(wrr, 0, n)


def warm_up_refinement() -> None:
    """The refinement's and the surface mask's compiled passes loaded now (compiled once after an install), on a
    frame's argument types: the patch a view of a wider crop, its mask an array of its own."""
    ramp = np.tile(np.arange(24, dtype=np.float32) * 9, (6, 1))
    PatchAligner(ramp, ramp, (4, 0, 20, 6)).refine(np.ones((6, 16), bool), 2.0, iterations=1)
    surface_mask(ramp, ramp, (12, 0, 20, 6), 5.0)


def refine_disparity(left: np.ndarray, right: np.ndarray, box: tuple[int, int, int, int], mask: np.ndarray | None,
                     d0: float, iterations: int = 10, huber: float = 6.0, tol: float = 1e-3) -> Refined | None:
    """Disparity [px] of the pixels of ``box`` (u0, v0, u1, v1) in ``mask`` ((v1-v0, u1-u0) bool, None = all),
    starting from ``d0``; float32 grey images of one size. None when the patch has no texture or leaves the image.
    One alignment; ``PatchAligner`` shares the preparation between several."""
    return PatchAligner(left, right, box).refine(mask, d0, iterations, huber, tol)
