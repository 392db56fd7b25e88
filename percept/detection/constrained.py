"""The constrained search: only the windows where a person standing on the road can appear.

A person of height H [m] whose feet touch the road at camera depth Z stands on image row v_feet (the rig's ground
projection) and is fy H / Z pixels tall; the 64x128 window holds a person 96 px tall with 16 px below the feet
(Dalal & Triggs' training crops), so at window scale s (a window 128 s px tall) the person is 96 s px tall and
Z = fy H / (96 s). People are 1.0-2.1 m tall, so each scale admits a narrow band of feet rows, and only the
corridor's columns (within ``half_width_m`` of the ego path) at those depths: every other window is impossible
and never scored. For each scale the band is cropped from the image (with the window's height above it), resized
once and its HOG blocks computed once (``hog.block_grid``).

Cells of ``cell_px`` = 4 pixels on the strip resized by 0.5 / s see what Dalal & Triggs' 8-pixel cells see on the
strip resized by 1 / s (the window is then 32x64 px): a quarter of the pixels at every scale, so the far field
(people of 24-48 px, s < 0.5, near the horizon) is upsampled by at most 2 rather than 4 — the "approximate
neighbouring scales" idea of Dollar et al., "Fast Feature Pyramids for Object Detection", PAMI 2014.

``search`` takes the levels (scale indices) to search and regions of interest (windows predicted by a tracker,
searched at their neighbouring scales only): the vision slot spreads the levels over frames and searches around
its tracks every frame. A model with a second stage (``LinearModel.second``) keeps only the detections it
confirms. ``SearchStats`` counts the windows scored against those of the full pyramid.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Iterable, Sequence

import cv2
import numpy as np

from percept.sensors import EgoPath, StereoRig

from .hog import CELL_PX, WINDOW_PX, LinearModel, block_grid
from .pyramid import Detection, group, lone_windows, second_stage_kept

PERSON_PX = 96
"""Height of the person inside a 64x128 window [px]."""
FEET_MARGIN_PX = 16
"""Window rows below the person's feet [px]."""
Box = tuple[float, float, float, float]


@dataclass(frozen=True)
class SearchConfig:
    """Settings of the constrained search: which people, where, and at which scales and thresholds."""

    heights_m: tuple[float, float] = (1.0, 2.1)  # plausible person heights [m]
    min_person_px: float = 24.0  # the smallest person searched for [px]
    min_range_m: float = 4.0  # nearest depth searched [m]
    max_range_m: float = 40.0  # farthest depth searched [m]
    half_width_m: float = 5.5  # the corridor about the ego path (its lane, the next lane's width and the verge) [m]
    step: float = 1.2  # scale step of the pyramid
    cell_px: int = 4  # HOG cell on the resized strip [px] (8 = Dalal & Triggs' own scale, 4 = a quarter of the pixels)
    threshold: float = 0.0  # smallest window score kept
    group_threshold: int = 1  # as ``detectMultiScale``'s: clusters of fewer than this + 1 windows are dropped
    lone_threshold: float | None = 0.25  # smallest score of a lone window (one grouping drops) kept; None: none kept


@dataclass(frozen=True)
class SearchStats:
    """windows: windows scored; full_windows: windows a full pyramid over the same scales would score (8-pixel
    stride, every scale); levels: scales searched."""

    windows: int
    full_windows: int
    levels: int

    @property
    def removed(self) -> float:
        """Fraction of the full pyramid's windows the constraint never scores."""
        return 1.0 - self.windows / self.full_windows if self.full_windows else 0.0


PERSON_WIDTH_FRAC = 0.4
"""Width of a person box as a fraction of its height."""


def standing_box(cu: float, v_feet: float, height_px: float) -> Box:
    """The person box (u0, v0, u1, v1) of someone ``height_px`` tall whose feet are at (cu, v_feet)."""
    half = PERSON_WIDTH_FRAC / 2 * height_px
    return (cu - half, v_feet - height_px, cu + half, v_feet)


def person_box(window: Box) -> Box:
    """The person inside a detection window (u0, v0, u1, v1): the middle 96/128 of its height (16/128 above the
    head and below the feet), ``PERSON_WIDTH_FRAC`` of the person's height wide about the window's centre."""
    u0, v0, u1, v1 = window
    m = (v1 - v0) * FEET_MARGIN_PX / WINDOW_PX[1]
    return standing_box((u0 + u1) / 2, v1 - m, (v1 - v0) - 2 * m)


class ConstrainedSearch:
    """People standing on the road in a rig's left image; ``search(image, path)`` -> (detections, stats)."""

    def __init__(self, rig: StereoRig, model: LinearModel, cfg: SearchConfig = SearchConfig()):
        self.rig, self.model, self.cfg = rig, model, cfg
        cam = rig.camera
        h_lo, h_hi = cfg.heights_m
        # window scales from the smallest person (shortest, farthest) to the largest (tallest, nearest)
        s_min = max(cam.fy * h_lo / (PERSON_PX * cfg.max_range_m), cfg.min_person_px / PERSON_PX)
        s_max = min(cam.fy * h_hi / (PERSON_PX * cfg.min_range_m), cam.height / WINDOW_PX[1])
        n = int(np.floor(np.log(s_max / s_min) / np.log(cfg.step))) + 1
        self.scales = s_min * cfg.step ** np.arange(n)
        self.cam_x = float(rig.camera_position()[0])
        self.depths = tuple(self._depth_range(float(s)) for s in self.scales)
        # what a full pyramid over the same scales scores: every window at an 8-pixel stride, for the count
        self.full_windows = int(sum(max(int(cam.width / s - WINDOW_PX[0]) // CELL_PX + 1, 0)
                                    * max(int(cam.height / s - WINDOW_PX[1]) // CELL_PX + 1, 0) for s in self.scales))
        # the compiled kernels (the blocks' and the window sums', compiled once after an install) loaded now, on
        # one window of the strips' kind (BGR uint8, cfg.cell_px cells), not in a timed frame; and the grouping's,
        # on two windows of the search's kind (whole pixels in int32, float32 scores) grouped into one detection
        c = cfg.cell_px
        window = np.zeros((WINDOW_PX[1] * c // CELL_PX, WINDOW_PX[0] * c // CELL_PX, 3), np.uint8)
        model.score_map(block_grid(window, c))
        boxes, scores = np.array([[0, 0, 32, 64], [1, 0, 32, 64]], np.int32), np.ones(2, np.float32)
        second_stage_kept(group(boxes, scores, 1) + lone_windows(boxes, scores), boxes, scores, 0.0)

    def _depth_range(self, scale: float) -> tuple[float, float] | None:
        """The camera depths (near, far) [m] of the people a window of ``scale`` holds, within the searched
        depths; None when there are none."""
        cam, cfg = self.rig.camera, self.cfg
        h_lo, h_hi = cfg.heights_m
        # Z = fy H / (96 s) for the shortest and the tallest person, within the searched depths
        z_near = max(cam.fy * h_lo / (PERSON_PX * scale), cfg.min_range_m)
        z_far = min(cam.fy * h_hi / (PERSON_PX * scale), cfg.max_range_m)
        return None if z_near > z_far else (z_near, z_far)

    def region(self, level: int, path: EgoPath) -> tuple[int, int, int, int] | None:
        """The image region (u0, v0, u1, v1) that holds every plausible window at scale ``level``, or None."""
        return self.regions((level,), path)[0][1]

    def regions(self, levels: Iterable[int], path: EgoPath) -> list[tuple[int, tuple[int, int, int, int] | None]]:
        """(level, ``region``) of each of ``levels``; the corridor's corners of every level projected at once (the
        same values as one level at a time: every step is element by element)."""
        cfg, levels = self.cfg, tuple(levels)
        ks = [k for k in levels if self.depths[k] is not None]
        if not ks:
            return [(k, None) for k in levels]
        # the path's centre at the nearest and the farthest person's feet of every level
        x = self.cam_x + np.array([z for k in ks for z in self.depths[k]])
        centre, xs = path.centre_y(x).tolist(), x.tolist()
        pts = np.array([[xs[i], centre[i] + side * cfg.half_width_m, 0.0] for i in range(len(xs)) for side in (-1, 1)])
        uv = self.rig.project_vehicle_points(pts)[0].tolist()
        found = {}
        for n, k in enumerate(ks):
            scale, (us, vs) = float(self.scales[k]), zip(*uv[4 * n:4 * n + 4])
            u_min, u_max, v_min, v_max = min(us), max(us), min(vs), max(vs)
            # feet rows of the nearest and farthest person; the window reaches 112 s px above the feet and 16 s below
            v_top = v_min - (WINDOW_PX[1] - FEET_MARGIN_PX) * scale
            v_bot = v_max + FEET_MARGIN_PX * scale
            u0, u1 = u_min - WINDOW_PX[0] * scale / 2, u_max + WINDOW_PX[0] * scale / 2
            found[k] = self.clip((u0, v_top, u1, v_bot), scale)
        return [(k, found.get(k)) for k in levels]

    def clip(self, box: Box, scale: float) -> tuple[int, int, int, int] | None:
        """``box`` clipped to the image in whole pixels, or None when a window at ``scale`` no longer fits in it."""
        cam = self.rig.camera
        # (clipped before rounding, which a corner at infinity could not be)
        b = (math.floor(max(box[0], 0)), math.floor(max(box[1], 0)), math.ceil(min(box[2], cam.width)),
             math.ceil(min(box[3], cam.height)))
        if b[2] - b[0] < WINDOW_PX[0] * scale or b[3] - b[1] < WINDOW_PX[1] * scale:
            return None
        return b

    def levels_around(self, window: Box) -> range:
        """The two levels whose window heights bracket that of ``window`` (one at the ends of the pyramid)."""
        k = np.log((window[3] - window[1]) / WINDOW_PX[1] / self.scales[0]) / np.log(self.cfg.step)
        lo = int(np.clip(np.floor(k), 0, len(self.scales) - 1))
        return range(lo, min(lo + 2, len(self.scales)))

    def _roi_regions(self, rois: Sequence[Box]) -> list[tuple[int, tuple[int, int, int, int]]]:
        """(level, region) around each predicted window: the levels bracketing it, half a window either side."""
        out = []
        for r in rois:
            for k in self.levels_around(r):
                s = float(self.scales[k])
                cu, cv = (r[0] + r[2]) / 2, (r[1] + r[3]) / 2
                # the window at this scale, centred on the prediction, grown by half a window either way
                half_w, half_h = WINDOW_PX[0] * s, 0.75 * WINDOW_PX[1] * s
                box = self.clip((cu - half_w, cv - half_h, cu + half_w, cv + half_h), s)
                if box is not None:
                    out.append((k, box))
        return out

    def _scan(self, image: np.ndarray, level: int, region: tuple[int, int, int, int]):
        """Windows of one region at one scale: boxes (N, 4) as (x, y, w, h) and scores (N,), and the count."""
        cfg, s = self.cfg, float(self.scales[level])
        u0, v0, u1, v1 = region
        c = cfg.cell_px
        # the strip resized so that c-pixel cells see what 8-pixel cells see at scale s: f = (c / 8) / s
        f = c / CELL_PX / s
        size = (max(int(round((u1 - u0) * f)), 8 * c), max(int(round((v1 - v0) * f)), 16 * c))
        crop = cv2.resize(image[v0:v1, u0:u1], size, interpolation=cv2.INTER_LINEAR)
        blocks = block_grid(crop, c)
        scores = self.model.score_map(blocks)
        x, y = (scores >= cfg.threshold).nonzero()
        if not len(x):
            # no window at the threshold (most strips): nothing to place, nothing for a second stage to score
            none = np.zeros(0, np.float32)
            return np.zeros((0, 4)), none, None if self.model.second is None else none, scores.size
        sx, sy = (u1 - u0) / size[0], (v1 - v0) / size[1]
        boxes = np.column_stack([u0 + x * c * sx, v0 + y * c * sy, np.full(len(x), 8 * c * sx),
                                 np.full(len(x), 16 * c * sy)])
        return boxes, scores[x, y], self.model.second_scores(blocks, x, y), scores.size

    def windows(self, image: np.ndarray, path: EgoPath, levels: Iterable[int] | None = None,
                rois: Sequence[Box] = ()) -> tuple[np.ndarray, np.ndarray, SearchStats]:
        """Every window scoring at least the threshold, before grouping: boxes (N, 4) as (x, y, w, h) [px], scores
        (N,), and the counts."""
        boxes, scores, _, stats = self._windows(image, path, levels, rois)
        return boxes, scores, stats

    def _windows(self, image, path, levels, rois) -> tuple[np.ndarray, np.ndarray, np.ndarray | None, SearchStats]:
        """``windows`` and the windows' second-stage scores (N,) (None when the model has no second stage)."""
        todo = self.regions(range(len(self.scales)) if levels is None else levels, path)
        todo = [t for t in todo if t[1] is not None] + self._roi_regions(rois)
        boxes, scores, windows = [np.zeros((0, 4))], [np.zeros(0, np.float32)], 0
        second = None if self.model.second is None else [np.zeros(0, np.float32)]
        for k, region in todo:
            b, sc, s2, n = self._scan(image, k, region)
            boxes.append(b)
            scores.append(sc)
            if second is not None:
                second.append(s2)
            windows += n
        stats = SearchStats(windows, self.full_windows, len({k for k, _ in todo}))
        return np.concatenate(boxes), np.concatenate(scores), None if second is None else np.concatenate(second), stats

    def search(self, image: np.ndarray, path: EgoPath, levels: Iterable[int] | None = None,
               rois: Sequence[Box] = ()) -> tuple[list[Detection], SearchStats]:
        """Detections (windows, best first) at ``levels`` (default: every scale) over the corridor, and at the
        neighbouring scales of each region of interest; then the lone windows scoring ``lone_threshold``."""
        boxes, scores, second, stats = self._windows(image, path, levels, rois)
        boxes = np.round(boxes).astype(np.int32)
        dets = group(boxes, scores, self.cfg.group_threshold)
        if self.cfg.lone_threshold is not None and self.cfg.group_threshold >= 1:
            dets += [d for d in lone_windows(boxes, scores) if d.score >= self.cfg.lone_threshold]
        return second_stage_kept(dets, boxes, second, self.model.second_threshold), stats
