"""Lane-marking evidence: bright stripes of marking width on the road, found in a bird's-eye view.

The road region the rig's geometry predicts is warped to a metric top-down grid through the ground-plane
homography (Hartley & Zisserman, sec. 8.1), where a marking has the same width at every distance. A
symmetric top-hat — the stripe brighter than *both* flanks at 1.5 widths — keeps paired rising/falling
edges of the expected width and rejects wide bright things (cars, sky), slow shading (shadows, glare,
night beams) and single edges (Veit et al., "Evaluation of road marking feature extraction", ITSC 2008).
Yellow and white both score high on max(R, G).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from enum import Enum

import cv2
import numpy as np

from percept.compiled import kernel
from percept.sensors import Side, StereoRig

from .types import MarkingEvidence
from .vehicles import VehicleConfig, find_vehicles, mask_evidence


class Brightness(str, Enum):
    """How bright a pixel is as paint: MAX_RG = max(R, G) (white and yellow on dark asphalt); MAX_RG_YELLOW also
    lifts yellow above pale concrete, where max(R, G) barely differs."""

    MAX_RG = "max_rg"
    MAX_RG_YELLOW = "max_rg_yellow"


def marking_brightness(image: np.ndarray) -> np.ndarray:
    """MAX_RG_YELLOW of a BGR image (same shape without channels), float32 [grey levels]:
    max(max(R, G), B + 2 ((R + G) / 2 - B)); the yellowness term (R + G) / 2 - B lifts a yellow line."""
    b, g, r = (image[..., k].astype(np.float32) for k in range(3))
    return np.maximum(np.maximum(r, g), b + 2.0 * np.clip((r + g) / 2 - b, 0, None))


@dataclass(frozen=True)
class EvidenceConfig:
    """Settings of the marking evidence: the bird's-eye grid, the stripe test and what is not road."""

    x_near_m: float = 6.0  # nearest ground range ahead of the vehicle centre [m]
    x_far_m: float = 50.0  # farthest ground range ahead of the vehicle centre [m]
    half_width_m: float = 8.0  # lateral half range [m]
    dx_m: float = 0.25  # grid step along the road [m]
    dy_m: float = 0.05  # grid step across the road [m]
    marking_width_m: float = 0.15  # expected stripe width [m]
    # a point counts fully where one pixel spans at most this much ground across [m]; further away its weight falls as
    # the span squared
    full_weight_span_m: float = 0.025
    min_contrast: float = 10.0  # absolute top-hat threshold [grey levels]
    rel_contrast: float = 0.3  # threshold relative to the frame's strong responses
    brightness: Brightness = Brightness.MAX_RG  # the paint measure
    max_row_px: float | None = None  # image rows below this are not road (a car's hood) [px]; None: all rows
    # None: grid rows every dx_m; else every row_step_px image rows where that is closer (near the camera, where a
    # dx_m step skips many image rows), never further apart than dx_m [px]
    row_step_px: float | None = None
    # None: keep all evidence; else the evidence a vehicle covers is dropped (``vehicles.find_vehicles``)
    vehicles: VehicleConfig | None = None

    def __post_init__(self) -> None:
        if not 0 < self.x_near_m < self.x_far_m:
            raise ValueError(f"need 0 < x_near_m < x_far_m, got {self.x_near_m}, {self.x_far_m}")
        if self.dx_m <= 0 or self.dy_m <= 0:
            raise ValueError("grid steps dx_m, dy_m must be positive")
        if not self.full_weight_span_m > 0:
            raise ValueError(f"full_weight_span_m must be positive, got {self.full_weight_span_m}")
        if self.row_step_px is not None and not self.row_step_px > 0:
            raise ValueError(f"row_step_px must be positive, got {self.row_step_px}")


def grid_ranges(rig: StereoRig, cfg: EvidenceConfig, side: Side = Side.LEFT) -> np.ndarray:
    """Ground ranges [m] of the bird's-eye grid rows, near to far: every dx_m, or (row_step_px set) equally spaced
    in s with ds/dx = max(|dv/dx| / row_step_px, 1 / dx_m), v(x) the image row of the ground at range x."""
    if cfg.row_step_px is None:
        rows = int(round((cfg.x_far_m - cfg.x_near_m) / cfg.dx_m)) + 1
        return cfg.x_near_m + cfg.dx_m * np.arange(rows)
    fine = np.linspace(cfg.x_near_m, cfg.x_far_m, 4096)
    vh = rig.ground_homography(side) @ np.stack([fine, np.zeros_like(fine), np.ones_like(fine)])
    dvdx = np.abs(np.gradient(vh[1] / vh[2], fine))
    rate = np.maximum(dvdx / cfg.row_step_px, 1.0 / cfg.dx_m)
    # s(x) = integral of ds/dx (trapezoids); rows at whole steps of s
    s = np.concatenate([[0.0], np.cumsum((rate[1:] + rate[:-1]) / 2 * np.diff(fine))])
    return np.interp(np.arange(int(np.floor(s[-1])) + 1), s, fine)


class MarkingExtractor:
    """Finds marking evidence in one camera image (BGR, the rig's size)."""

    def __init__(self, rig: StereoRig, cfg: EvidenceConfig = EvidenceConfig(), side: Side = Side.LEFT):
        self.rig, self.cfg = rig, cfg
        self.x = grid_ranges(rig, cfg, side)
        self.rows = len(self.x)
        self.cols = int(round(2 * cfg.half_width_m / cfg.dy_m)) + 1
        self.y = cfg.half_width_m - cfg.dy_m * np.arange(self.cols)
        # grid pixel (c, r) -> ground (x_r, y_c), y_c = half_width - c dy -> image through the ground homography
        uv = rig.ground_homography(side) @ np.stack([np.repeat(self.x, self.cols), np.tile(self.y, self.rows),
                                                     np.ones(self.rows * self.cols)])
        self.uv = (uv[:2] / uv[2]).T.reshape(self.rows, self.cols, 2)
        cam = rig.camera
        bottom = cam.height - 1 if cfg.max_row_px is None else min(cfg.max_row_px, cam.height - 1)
        self.valid = ((self.uv[..., 0] >= 0) & (self.uv[..., 0] <= cam.width - 1) & (self.uv[..., 1] >= 0)
                      & (self.uv[..., 1] <= bottom))
        self.valid_f = self.valid.astype(np.float32)
        # weight of a grid row: image rows per grid row (far rows re-sample one image row many times), capped at 1,
        # times the lateral precision (sigma_y = x / f per pixel): w = min(1, |dv/dr|) min(1, (f s / x)^2)
        dv = np.abs(np.gradient(self.uv[:, self.cols // 2, 1]))
        self.row_weight = np.minimum(1.0, dv) * np.minimum(1.0, (rig.camera.fx * cfg.full_weight_span_m / self.x) ** 2)
        self.w_px = max(int(round(cfg.marking_width_m / cfg.dy_m)), 1)
        self.size = (cam.width, cam.height)
        # grid -> image lookup for cv2.remap, in OpenCV's fast fixed-point form; rows below max_row_px read black
        uv = np.where(self.valid[..., None], self.uv, -10.0).astype(np.float32)
        self.map1, self.map2 = cv2.convertMaps(uv[..., 0], uv[..., 1], cv2.CV_16SC2)
        # the compiled passes (compiled once after an install) loaded now, on a grid's argument types, not in a timed
        # frame
        resp, _ = _top_hat(np.zeros(self.valid_f.shape, np.float32), 2, self.valid_f, np.float32(cfg.min_contrast))
        _row_peaks(resp, np.float32(np.inf))

    def birdseye(self, image: np.ndarray) -> np.ndarray:
        """Top-down marking brightness (rows, cols) float32; rows go from near to far."""
        if image.shape[1::-1] != self.size:
            raise ValueError(f"image is {image.shape[1]}x{image.shape[0]}, "
                             f"the rig expects {self.size[0]}x{self.size[1]}")
        # one remap of the colour image through the precomputed fixed-point grid, then the paint measure on the
        # (smaller) grid
        top = cv2.remap(image, self.map1, self.map2, cv2.INTER_LINEAR)
        if self.cfg.brightness is Brightness.MAX_RG:
            return cv2.max(top[..., 1], top[..., 2]).astype(np.float32)
        return marking_brightness(top)

    def extract(self, image: np.ndarray) -> MarkingEvidence:
        """The marking evidence of one BGR image: one point per stripe per bird's-eye grid row."""
        b = self.birdseye(image)
        w = self.w_px
        # top-hat: centre mean minus the brighter of the two flank means at 1.5 widths (the flank means are the
        # same box means shifted by s columns; the s columns at each side get no response)
        centre = cv2.blur(b, (w, 1))
        resp, strong = _top_hat(centre, int(round(1.5 * w)) + 1, self.valid_f, np.float32(self.cfg.min_contrast))
        if strong.size:
            # 90th percentile of the strong responses
            k = int(0.9 * (strong.size - 1))
            thr = max(self.cfg.min_contrast, self.cfg.rel_contrast * float(np.partition(strong, k)[k]))
        else:
            thr = np.inf
        # one point per stripe per row: local maxima along the row above the threshold
        r, c = _row_peaks(resp, np.float32(thr))
        v = resp[r, c]
        pts = np.column_stack([self.x[r], self.y[c]])
        ev = MarkingEvidence(pts, v, self.uv[r, c], self.row_weight[r])
        if self.cfg.vehicles is None:
            return ev
        boxes = find_vehicles(image, self.rig, self.cfg.max_row_px, self.cfg.vehicles)
        return replace(mask_evidence(ev, boxes, self.rig.horizon_row, self.cfg.vehicles.pad), vehicles=tuple(boxes))


@kernel()
def _top_hat(centre, s, valid, min_contrast):  # pragma: no cover - compiled
    """The top-hat response (rows, cols) float32 of the box means ``centre``: centre - max(centre s columns left,
    centre s columns right), times ``valid`` (0 in the s columns at each side), and the responses above
    ``min_contrast`` in row-major order (numpy's ``resp[resp > min_contrast]``). float32 throughout, as numpy."""
    rows, cols = centre.shape
    resp = np.zeros((rows, cols), np.float32)
    strong = np.empty(rows * cols, np.float32)
    n = 0
    for y in range(rows):
        for x in range(cols):
            if s <= x < cols - s:
                resp[y, x] = centre[y, x] - max(centre[y, x - s], centre[y, x + s])
            resp[y, x] *= valid[y, x]
            if resp[y, x] > min_contrast:
                strong[n] = resp[y, x]
                n += 1
    return resp, strong[:n]


@kernel()
def _row_peaks(resp, thr):  # pragma: no cover - compiled
    """Rows and columns (N,) of the pixels above ``thr`` that are a maximum along their row (>= the left neighbour,
    > the right one), columns 1..cols - 2, in row-major order."""
    rows, cols = resp.shape
    r, c = np.empty(rows * cols, np.int64), np.empty(rows * cols, np.int64)
    n = 0
    for y in range(rows):
        for x in range(1, cols - 1):
            v = resp[y, x]
            if v > thr and v >= resp[y, x - 1] and v > resp[y, x + 1]:
                r[n], c[n] = y, x
                n += 1
    return r[:n], c[:n]
