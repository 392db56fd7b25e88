"""The road plane under the ego, refined online from the stereo points that lie on it.

The rig's calibration says where the road is (its height and pitch); a load, a braking dive or a slope ahead
moves it. Stereo points near the road, lifted with the calibration, fit z = a + b x in the vehicle frame each frame
(trimmed to a band about the current estimate; a line through the median height of each range bin, so that the
many near points do not outvote the far ones; exponentially smoothed): a is a height error, b a pitch error (rad)
or the grade change ahead. Heights above the road are then measured from that plane, so
that the road far ahead does not "stand up" when the camera pitches (the v-disparity idea of Labayrade et al.,
IV 2002, as a plane fit). The correction is applied once it moves a height at ``ref_range_m`` by more than
``deadband_m``: a well calibrated rig is left as it is rather than made to follow the fit's noise.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from percept.compiled import floor_divide, kernel

from .quantiles import median


@dataclass(frozen=True)
class GroundConfig:
    """Settings of the online road-plane fit: which points are road, how they are binned, how often and how much."""

    band_m: float = 0.5  # points within this of the current plane are road [m]
    # image columns x range cells [px, m] with a point up to max_standing_m above the band give no road points (they
    # are an obstacle's low parts)
    cell_px: int = 16
    cell_m: float = 3.0
    max_standing_m: float = 3.5
    # the fit's range [m]: the near band's, where the road's disparities are large and unbiased (the coarse far band's
    # road heights are off by up to 0.1 m)
    min_range_m: float = 4.0
    max_range_m: float = 16.0
    half_width_m: float = 6.0  # the fit's lateral reach [m]
    bin_m: float = 2.0  # range bins [m]
    min_points: int = 200  # fewest points for a bin's median
    smoothing: float = 0.25  # weight of each new fit (exponential smoothing)
    every_frames: int = 3  # fit every this many frames
    # the correction is applied while it moves a height at ref_range_m by more than deadband_m [m] (0.2 m at 30 m: a
    # 0.4 degree pitch), so that a well calibrated rig does not follow the fit's noise
    ref_range_m: float = 30.0
    deadband_m: float = 0.2


class GroundPlane:
    """``update(points)`` refines the plane from vehicle-frame stereo points (N, 3); ``height(points)`` is their
    height above it [m]. ``offset_m``, ``slope``: the plane z = offset + slope x; ``active``: applied."""

    def __init__(self, cfg: GroundConfig = GroundConfig()):
        self.cfg = cfg
        self.reset()

    def reset(self) -> None:
        self.offset_m, self.slope, self.active = 0.0, 0.0, False
        self.frames = 0

    def _plane(self, x: np.ndarray) -> np.ndarray:
        return self.offset_m + self.slope * x

    def update(self, points: np.ndarray, u_px: np.ndarray) -> None:
        """Refine from vehicle-frame points (N, 3) and their image columns (N,) [px] (every ``every_frames``; the
        columns are taken as float32, the finder's pixel centres)."""
        if np.shape(points)[1:] != (3,) or len(points) != len(u_px):
            raise ValueError(f"need points (N, 3) and columns (N,), got {np.shape(points)} and {np.shape(u_px)}")
        cfg = self.cfg
        self.frames += 1
        if (self.frames - 1) % cfg.every_frames:
            return
        x, zs = _road_points(points, np.asarray(u_px, np.float32), self.offset_m, self.slope, cfg.band_m,
                             cfg.min_range_m, cfg.max_range_m, cfg.half_width_m, np.float32(cfg.cell_px), cfg.cell_m,
                             cfg.max_standing_m)
        k = np.floor((x - cfg.min_range_m) / cfg.bin_m).astype(int)
        counts = np.bincount(k)
        bins = np.flatnonzero(counts >= cfg.min_points)
        if len(bins) < 4:
            return
        med = np.array([median(zs[k == b]) for b in bins])
        xc = cfg.min_range_m + (bins + 0.5) * cfg.bin_m
        # least squares z = a + b x through the bins' medians
        (b, a) = np.polyfit(xc, med, 1)
        w = cfg.smoothing
        self.offset_m += w * (float(a) - self.offset_m)
        self.slope += w * (float(b) - self.slope)
        self.active = abs(self.offset_m + self.slope * cfg.ref_range_m) > cfg.deadband_m

    def height(self, points: np.ndarray) -> np.ndarray:
        """Height above the road of vehicle-frame points (N, 3) [m]: above the fitted plane once it is applied."""
        return points[:, 2] - self._plane(points[:, 0]) if self.active else points[:, 2]


@kernel()
def _road_points(points, u_px, offset, slope, band, x_min, x_max, half_width, cell_px, cell_m,
                 max_standing):  # pragma: no cover - compiled
    """The ranges x and heights z (N,) float64 of the points (N, 3) [m] that lie on the road plane z = offset +
    slope x: within ``band`` of it, x in (x_min, x_max), |y| < half_width, and in no cell (image column // cell_px
    x range // cell_m) that also holds a point standing band..max_standing above it at x > 0 (not the low parts of
    what stands on the road: bumpers, tyres), among the points of the range cells the fit uses. In numpy's
    arithmetic (column // cell_px is float32 floor division)."""
    # a cell of a power of two pixels divides a column exactly (as a product with its exact inverse), and then the
    # floor of the quotient is numpy's floor division (npy_divmod) already, without its fmod (~60% of this pass)
    exact, inverse = math.frexp(cell_px)[0] == 0.5, np.float32(1) / cell_px
    lo = np.floor(x_min / cell_m) * cell_m
    hi = (np.floor(x_max / cell_m) + 1) * cell_m
    n = points.shape[0]
    h, cu, cx = np.empty(n), np.empty(n, np.int64), np.empty(n, np.int64)
    inside, up = np.zeros(n, np.bool_), np.zeros(n, np.bool_)
    u_lo, u_hi, x_lo, x_hi = 1 << 40, -(1 << 40), 1 << 40, -(1 << 40)
    for i in range(n):
        x = points[i, 0]
        if not (x >= lo and x < hi):
            continue
        inside[i] = True
        h[i] = points[i, 2] - (offset + slope * x)
        # numpy's float32 floor division of the column by the cell
        cu[i] = np.int64(np.floor(u_px[i] * inverse) if exact else floor_divide(u_px[i], cell_px))
        cx[i] = np.int64(np.floor(x / cell_m))
        up[i] = h[i] > band and h[i] < max_standing and x > 0
        if up[i]:
            u_lo, u_hi, x_lo, x_hi = min(u_lo, cu[i]), max(u_hi, cu[i]), min(x_lo, cx[i]), max(x_hi, cx[i])
    # the cells holding a standing point, over the box of those cells
    standing = np.zeros((max(u_hi - u_lo + 1, 0), max(x_hi - x_lo + 1, 0)), np.bool_)
    for i in range(n):
        if up[i]:
            standing[cu[i] - u_lo, cx[i] - x_lo] = True
    xs, zs = np.empty(n), np.empty(n)
    m = 0
    for i in range(n):
        if not inside[i]:
            continue
        x = points[i, 0]
        if not (x > x_min and x < x_max and abs(points[i, 1]) < half_width and abs(h[i]) < band):
            continue
        a, b = cu[i] - u_lo, cx[i] - x_lo
        if 0 <= a < standing.shape[0] and 0 <= b < standing.shape[1] and standing[a, b]:
            continue
        xs[m], zs[m] = x, points[i, 2]
        m += 1
    return xs[:m], zs[:m]
