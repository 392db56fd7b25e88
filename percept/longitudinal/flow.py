"""Time to contact from the expansion of the obstacle's image: KLT features on it, tracked over a few frames.

An object at range Z images at a size proportional to 1/Z, so between two frames the distances between its
features scale by s = Z0 / Z1; the time to contact is tau = dt / (s - 1) and the range rate is
dZ/dt = -Z1 (s - 1) / dt (Lee 1976; Camus 1995; Hartley & Zisserman for the pinhole model). The scale is the
median of the ratios of pairwise feature distances, which ignores features that slide across the object's
outline; tracks are checked forwards and backwards (Kalal et al. 2010).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import cv2
import numpy as np

from percept.compiled import kernel

from .quantiles import median


@dataclass(frozen=True)
class FlowConfig:
    """Settings of the expansion measurement: the time baseline, the features, the KLT tracker and the pairs used."""

    # the scale is measured against the frame this many frames earlier (a longer baseline in time resolves slower
    # expansion)
    frames_back: int = 4
    max_features: int = 80  # goodFeaturesToTrack's maxCorners
    quality: float = 0.002  # goodFeaturesToTrack's qualityLevel
    min_distance_px: int = 2  # goodFeaturesToTrack's minDistance [px]
    win_px: int = 11  # the pyramidal KLT window [px]
    levels: int = 2  # the pyramidal KLT's pyramid levels
    fb_max_px: float = 0.3  # largest forward-backward error kept [px]
    min_pairs: int = 6  # fewest feature pairs for a measurement
    min_pair_px: float = 6.0  # shortest pair distance used [px]


@dataclass(frozen=True)
class Expansion:
    """scale: s = Z0 / Z1, the image scale change over dt_s [s]; sigma: its standard error; features: tracks kept.
    ``range_rate_mps(Z)`` and ``ttc_s`` follow from it."""

    scale: float
    sigma: float
    dt_s: float
    features: int

    def range_rate_mps(self, range_m: float) -> float:
        # dZ/dt = -Z1 (s - 1) / dt
        return -range_m * (self.scale - 1.0) / self.dt_s

    @property
    def ttc_s(self) -> float | None:
        # tau = dt / (s - 1), only while the object expands
        return self.dt_s / (self.scale - 1.0) if self.scale > 1.0 else None


class ExpansionTracker:
    """Keeps the last few left images (grey) with the obstacle's box; ``measure`` compares the newest with the
    oldest kept."""

    def __init__(self, cfg: FlowConfig = FlowConfig()):
        self.cfg = cfg
        self.history: deque = deque(maxlen=cfg.frames_back + 1)
        # the compiled pair ratios (compiled once after an install) loaded now, on a frame's argument types
        no_points = np.zeros((0, 2), np.float32)
        pair_ratios(no_points, no_points, float(cfg.min_pair_px))

    def reset(self) -> None:
        self.history.clear()

    def measure(self, gray: np.ndarray, box: tuple[int, int, int, int], t_s: float) -> Expansion | None:
        """Add this frame (grey image, the obstacle's box (u0, v0, u1, v1), its time [s]) and return the expansion
        since the oldest kept frame, or None (first frame, too few features, a box that moved off the image)."""
        self.history.append((gray, box, t_s))
        if len(self.history) < 2:
            return None
        g0, b0, t0 = self.history[0]
        return _expansion(g0, gray, b0, t_s - t0, self.cfg)


def _expansion(g0: np.ndarray, g1: np.ndarray, box: tuple[int, int, int, int], dt: float,
               cfg: FlowConfig) -> Expansion | None:
    """The expansion of the features of ``box`` (u0, v0, u1, v1) in grey image g0 tracked into g1, dt [s] later;
    None with too few features or pairs."""
    u0, v0, u1, v1 = box
    if dt <= 0 or u1 - u0 < 8 or v1 - v0 < 8:
        return None
    # features and tracks on a crop about the box (room for the motion), not the whole frame
    m = max(cfg.win_px * 2 ** cfg.levels, (u1 - u0) // 2)
    h, w = g0.shape
    c0, r0, c1, r1 = max(u0 - m, 0), max(v0 - m, 0), min(u1 + m, w), min(v1 + m, h)
    g0, g1 = g0[r0:r1, c0:c1], g1[r0:r1, c0:c1]
    mask = np.zeros(g0.shape, np.uint8)
    mask[v0 - r0:v1 - r0, u0 - c0:u1 - c0] = 255
    p0 = cv2.goodFeaturesToTrack(g0, cfg.max_features, cfg.quality, cfg.min_distance_px, mask=mask)
    if p0 is None or len(p0) < 5:
        return None
    lk = dict(winSize=(cfg.win_px, cfg.win_px), maxLevel=cfg.levels,
              criteria=(cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, 20, 0.01))
    p1, st1, _ = cv2.calcOpticalFlowPyrLK(g0, g1, p0, None, **lk)
    pb, st2, _ = cv2.calcOpticalFlowPyrLK(g1, g0, p1, None, **lk)
    # forward-backward consistency: the track back from frame 1 must land where it started
    # (the error's length as np.linalg.norm takes it: sqrt(dx^2 + dy^2) in float32)
    e = (pb - p0)[:, 0]
    ok = (st1[:, 0] == 1) & (st2[:, 0] == 1) & (np.sqrt(e[:, 0] * e[:, 0] + e[:, 1] * e[:, 1]) < cfg.fb_max_px)
    a, b = np.ascontiguousarray(p0[ok, 0]), np.ascontiguousarray(p1[ok, 0])
    if len(a) < 5:
        return None
    ratio = pair_ratios(a, b, float(cfg.min_pair_px))
    if len(ratio) < cfg.min_pairs:
        return None
    s = float(median(ratio))
    # robust spread (MAD) over about as many independent pairs as features
    mad = 1.4826 * float(median(np.abs(ratio - s)))
    sigma = max(mad, 1e-4) * np.sqrt(np.pi / 2) / np.sqrt(len(a))
    return Expansion(s, sigma, dt, int(len(a)))


@kernel()
def pair_ratios(a, b, min_pair_px):  # pragma: no cover - compiled
    """|b_i - b_j| / |a_i - a_j| (M,) float64 of every pair i < j (in that order: i, then j) of points a (N, 2)
    float32 whose distance |a_i - a_j| is at least ``min_pair_px``, b (N, 2) float32 the same points later; in
    float64 as numpy's ``np.linalg.norm(x, axis=1)`` takes them (sqrt(dx dx + dy dy)), so equal to it bit for
    bit."""
    n = a.shape[0]
    if b.shape[0] != n:
        raise ValueError("a and b hold different numbers of points")
    out = np.empty(n * (n - 1) // 2, np.float64)
    k = 0
    for i in range(n):
        for j in range(i + 1, n):
            dx, dy = np.float64(a[i, 0]) - np.float64(a[j, 0]), np.float64(a[i, 1]) - np.float64(a[j, 1])
            # d0 = |a_i - a_j|
            d0 = np.sqrt(dx * dx + dy * dy)
            if d0 >= min_pair_px:
                ex, ey = np.float64(b[i, 0]) - np.float64(b[j, 0]), np.float64(b[i, 1]) - np.float64(b[j, 1])
                out[k] = np.sqrt(ex * ex + ey * ey) / d0
                k += 1
    return out[:k]
