"""Vehicles over the markings, in one camera image: the dark road under a vehicle, with the vehicle above it.

A vehicle standing on the road shades the road under it, darker than any sunlit or overcast road; that shade ends
in a row where the road below is lit again, over the width of a vehicle at that row's range (Tzomakas & von Seelen,
"Vehicle detection in traffic scenes using shadows", IR-INI 98-06, 1998). A tree's shadow ends in such rows too; what
tells them apart is what lies above: a vehicle's body (bumper, lights, plate, wheels, windows) is full of edges,
shaded road is as smooth as the road below it; and lit road above a shade is road-coloured. So a bottom counts when
the mean gradient magnitude over the vehicle's first metre above it is ``edge_ratio`` times that of the road under
it and few of those pixels have the road's brightness.

A vehicle hides the markings behind it and its own edges pass the stripe test: the evidence in the columns of each
vehicle (10 % wider), from the horizon down to its bottom row, is dropped (``mask_evidence``). Used on footage only
(``EvidenceConfig.vehicles``); the simulator's fit does not use it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from percept.sensors import StereoRig, to_gray

from .types import MarkingEvidence


@dataclass(frozen=True)
class VehicleConfig:
    """Settings of the vehicle finder: the shade under a vehicle, the body above it and the mask over the evidence."""

    # the shade under a vehicle is darker than this share of the row's road level (the 60th percentile of the row's
    # middle 80 %)
    dark_ratio: float = 0.55
    lit_ratio: float = 0.8  # the road 3 rows below the shade is at least this share of its own row's level
    width_m: tuple[float, float] = (0.9, 3.2)  # (min, max) width of a vehicle's shade [m]
    gap_m: float = 0.25  # gaps in the shade closed up to this [m] (the wheels)
    edge_ratio: float = 1.5  # least mean gradient magnitude over the body against that of the road under it
    body_m: float = 1.0  # the height above the bottom over which the body is looked at [m]
    road_band: float = 0.2  # a body pixel within this share of the row's road level is road-like
    # the body's road-like pixels must be less than this share: a body is darker or brighter than the road, a
    # barrier's base or a strip of lit road above a shadow is not
    max_road_like: float = 0.4
    max_range_m: float = 60.0  # bottoms further than this are not looked for [m]
    pad: float = 0.1  # the mask is this share of the width wider on each side


@dataclass(frozen=True)
class VehicleBox:
    """A vehicle's shade: columns u0_px..u1_px (end exclusive) at image row bottom_px, range_m ahead [m] (flat
    road), edge_ratio: its body's mean gradient magnitude against the road's under it."""

    u0_px: int
    u1_px: int
    bottom_px: int
    range_m: float
    edge_ratio: float

    def covers(self, uv_px: np.ndarray, horizon_px: float, pad: float) -> np.ndarray:
        """(N,) bool: which image points (N, 2) (u, v) lie in the box widened by ``pad`` of its width a side, from
        the horizon down to two rows below its bottom."""
        m = pad * (self.u1_px - self.u0_px)
        u, v = uv_px[:, 0], uv_px[:, 1]
        return (u >= self.u0_px - m) & (u <= self.u1_px + m) & (v >= horizon_px - 1) & (v <= self.bottom_px + 2)


def _closed(starts: np.ndarray, ends: np.ndarray, k: int) -> list[tuple[int, int]]:
    """The runs [start, end) of a bool row after a morphological closing by a 1 x k segment: neighbouring runs
    merged where the gap between them is shorter than k."""
    out = []
    for a, b in zip(starts.tolist(), ends.tolist()):
        if out and a - out[-1][1] < k:
            out[-1] = (out[-1][0], b)
        else:
            out.append((a, b))
    return out


def find_vehicles(image: np.ndarray, rig: StereoRig, bottom_row_px: float | None = None,
                  cfg: VehicleConfig = VehicleConfig()) -> list[VehicleBox]:
    """Vehicles standing on the road in ``image`` (BGR or grey, the rig's size), nearest first; rows below
    ``bottom_row_px`` (a hood) are not road. The range of a row: x = fx h / (v - v_horizon)."""
    g = to_gray(image).astype(np.float32)
    H, W = g.shape
    hz, fx, h = rig.horizon_row, rig.camera.fx, rig.mount_height_m
    last = H - 1 if bottom_row_px is None else int(min(bottom_row_px, H - 1))
    # the nearest row whose range is within max_range_m, and 4 rows above the last (3 below must be road)
    top = int(math.ceil(hz + fx * h / cfg.max_range_m))
    if last - 4 <= top:
        return []
    # the rows below the horizon only (a body's window above the farthest bottom starts below it too)
    r0 = max(int(hz), 0)
    level = np.full(H, np.nan)
    level[r0:] = np.percentile(g[r0:, W // 10:W - W // 10], 60, axis=1)
    shade = g < cfg.dark_ratio * level[:, None]
    lit = g > cfg.lit_ratio * level[:, None]
    bottom = np.zeros_like(shade)
    bottom[:-3] = shade[:-3] & lit[3:]
    mag = np.zeros_like(g)
    below = g[r0:]
    mag[r0:] = cv2.magnitude(cv2.Sobel(below, cv2.CV_32F, 1, 0, ksize=3), cv2.Sobel(below, cv2.CV_32F, 0, 1, ksize=3))
    # every row's runs of shade bottom at once: where each starts and ends (row-major order)
    rows, cols = np.nonzero(np.diff(bottom.view(np.int8), axis=1, prepend=0, append=0))
    first = np.searchsorted(rows, np.arange(H + 1))
    taken = np.zeros(W, bool)
    out = []
    for v in range(last - 4, top - 1, -1):  # bottom up: the nearest first, which hides what is behind it
        i, j = first[v], first[v + 1]
        if i == j:
            continue
        x = fx * h / (v - hz)
        ppm = fx / x
        # the shade's gaps closed (the wheels, a bright plate's reflection)
        for a, b in _closed(cols[i:j:2], cols[i + 1:j:2], max(int(cfg.gap_m * ppm), 1)):
            if not cfg.width_m[0] <= (b - a) / ppm <= cfg.width_m[1] or taken[a:b].mean() > 0.3:
                continue
            body = max(int(cfg.body_m * ppm), 3)
            above = float(mag[max(v - body, 0):v - 1, a:b].mean())
            under = float(mag[v + 4:min(v + 4 + body // 2, H), a:b].mean()) if v + 5 < H else above
            ratio = above / max(under, 1.0)
            # and the body does not look like road: few of its pixels within road_band of the row's road level
            box = g[max(v - body, 0):v - 1, a:b]
            road_like = float((np.abs(box - level[v]) < cfg.road_band * level[v]).mean())
            if ratio >= cfg.edge_ratio and road_like < cfg.max_road_like:
                out.append(VehicleBox(a, b, v, x, ratio))
                taken[a:b] = True
    return out


def mask_evidence(ev: MarkingEvidence, boxes: list[VehicleBox], horizon_px: float,
                  pad: float = VehicleConfig.pad) -> MarkingEvidence:
    """``ev`` without the points any box covers (``VehicleBox.covers``)."""
    if not boxes or not len(ev.points_m):
        return ev
    hidden = np.zeros(len(ev.points_m), bool)
    for b in boxes:
        hidden |= b.covers(ev.uv_px, horizon_px, pad)
    keep = ~hidden
    return MarkingEvidence(ev.points_m[keep], ev.strength[keep], ev.uv_px[keep],
                           None if ev.weight is None else ev.weight[keep])
