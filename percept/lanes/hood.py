"""The car's own hood at the bottom of dash-camera footage: where the road ends in the image.

A hood is a surface of its own colour across the whole width of the bottom of the frame; its top edge is the
row where the colour above and below differs across most columns. A seam, a tar line or a shadow across the
road changes the road's brightness by a few grey levels, never its colour across the whole width: the median over
columns of the colour step between the rows above and below tells them apart (Udacity's hood: 50-92 grey levels;
road seams and the bottom of hood-less TuSimple and Udacity P1 frames: 11-43).
"""

from __future__ import annotations

import numpy as np

HOOD_STEP_GREY = 45.0
"""The median colour step (sum over B, G, R of |mean above - mean below|) a hood's edge makes [grey levels]."""
WIDE_STEP_SHARE = 0.6
"""A hood's step is still this share of HOOD_STEP_GREY between the rows beyond the k nearest on each side."""
MAX_CURVE_PX = 25
"""How far the hood's edge may curve from its median row across the image [px]."""


def hood_row(image: np.ndarray, band_frac: float = 0.3, rows: int = 8, blocks: int = 10) -> float | None:
    """Row [px] of the hood's top edge in a BGR image, or None. The image's columns are cut into ``blocks``; in each
    block of the middle 80 % the colour step (``rows`` rows above against ``rows`` rows below, summed over the
    channels, median over the block's columns) is followed up from the bottom to the first peak that reaches
    HOOD_STEP_GREY (a shadow's or a car's edge above the hood can step as much); a hood puts that peak within
    MAX_CURVE_PX of the blocks' median row in all but one of the blocks, and its edge (curved, most of all after
    undistortion) is reported at its highest block row. Rows within 2 ``rows`` of the bottom are not candidates
    (a dark border there is not a hood)."""
    img = np.asarray(image)
    if img.ndim != 3 or img.shape[2] != 3:
        raise ValueError(f"expected an (H, W, 3) BGR image, got shape {img.shape}")
    h, w = img.shape[:2]
    top = int((1 - band_frac) * h)
    f = img[top:].astype(np.float32)
    if len(f) < 5 * rows + 2 or w < blocks:
        return None
    # running sums down the columns: the mean of rows a..b-1 is (c[b] - c[a]) / (b - a)
    c = np.concatenate([np.zeros((1, w, 3), np.float32), np.cumsum(f, axis=0)])
    k = rows
    r = np.arange(2 * k, len(f) - 2 * k)
    # the step between the k rows above and the k rows below each row, and between the k rows beyond those (a line
    # thinner than k rows across the road, a seam or a tar line, makes the first but not the second)
    step = np.abs((c[r] - c[r - k]) - (c[r + k + 1] - c[r + 1])).sum(axis=2) / k
    wide = np.abs((c[r - k] - c[r - 2 * k]) - (c[r + 2 * k + 1] - c[r + k + 1])).sum(axis=2) / k
    edges = np.linspace(0, w, blocks + 1).astype(int)
    found = []
    for b in range(1, blocks - 1):
        score = np.median(step[:, edges[b]:edges[b + 1]], axis=1)
        strong = np.flatnonzero(score >= HOOD_STEP_GREY)
        if len(strong):
            # the lowest strong step (shadows and cars above the hood can step as much), at its peak
            i = strong[-1]
            while i > 0 and score[i - 1] >= score[i]:
                i -= 1
            if np.median(wide[i, edges[b]:edges[b + 1]]) >= WIDE_STEP_SHARE * HOOD_STEP_GREY:
                found.append(top + r[i])
    if len(found) < blocks - 3:
        return None
    # the blocks that agree on one edge (an odd block may peak on a car or a shadow above it)
    agree = [v for v in found if abs(v - np.median(found)) <= MAX_CURVE_PX]
    return float(min(agree)) if len(agree) >= blocks - 3 else None


def common_hood_row(images: list[np.ndarray]) -> float | None:
    """The hood row [px] of frames from one camera: the median of the frames' rows when at least half of them see a
    hood, else None."""
    found = [r for r in (hood_row(im) for im in images) if r is not None]
    return float(np.median(found)) if found and 2 * len(found) >= len(images) else None
