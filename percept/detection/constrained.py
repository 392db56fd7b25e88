"""The constrained search: only the windows where a person standing on the road can appear.

A person of height H [m] whose feet touch the road at camera depth Z stands on image row v_feet (the rig's ground
projection) and is fy H / Z pixels tall; the 64x128 window holds a person 96 px tall with 16 px below the feet
(Dalal & Triggs' training crops), so at window scale s (a window 128 s px tall) the person is 96 s px tall and
Z = fy H / (96 s). People are 1.0-2.1 m tall, so each scale admits a narrow band of feet rows, and only the
corridor's columns (within ``half_width_m`` of the ego path) at those depths: every other window is impossible
and never scored. For each scale the band is cropped from the image (with the window's height above it), resized
once and its HOG blocks computed once (``hog.block_grid``); scales below 1 (people under 96 px, the far field
near the horizon) upsample their strip, which is small. ``SearchStats`` counts the windows scored against those
of the full pyramid over the same scales.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from percept.sensors import EgoPath, StereoRig

from .hog import CELL_PX, WINDOW_PX, LinearModel, block_grid
from .pyramid import Detection, group

PERSON_PX = 96
"""Height of the person inside a 64x128 window [px]."""
FEET_MARGIN_PX = 16
"""Window rows below the person's feet [px]."""


@dataclass(frozen=True)
class SearchConfig:
    """heights_m: plausible person heights [m]; min_person_px: the smallest person searched for [px];
    min_range_m, max_range_m: depths searched [m]; half_width_m: the corridor about the ego path (its lane and the
    verges beside it) [m]; step: scale step of the pyramid; threshold: smallest window score kept;
    group_threshold: as ``detectMultiScale``'s."""

    heights_m: tuple[float, float] = (1.0, 2.1)
    min_person_px: float = 24.0
    min_range_m: float = 4.0
    max_range_m: float = 40.0
    half_width_m: float = 7.0
    step: float = 1.05
    threshold: float = 0.0
    group_threshold: int = 2


@dataclass(frozen=True)
class SearchStats:
    """windows: windows scored; full_windows: windows a full pyramid over the same scales would score; scales."""

    windows: int
    full_windows: int
    scales: int

    @property
    def removed(self) -> float:
        """Fraction of the full pyramid's windows the constraint never scores."""
        return 1.0 - self.windows / self.full_windows if self.full_windows else 0.0


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
        # what a full pyramid over the same scales scores: every window at an 8-pixel stride, for the count
        self.full_windows = int(sum(max(int(cam.width / s - WINDOW_PX[0]) // CELL_PX + 1, 0)
                                    * max(int(cam.height / s - WINDOW_PX[1]) // CELL_PX + 1, 0) for s in self.scales))

    def _region(self, scale: float, path: EgoPath) -> tuple[int, int, int, int] | None:
        """The image region (u0, v0, u1, v1) that holds every plausible window at ``scale``, or None."""
        cam, cfg = self.rig.camera, self.cfg
        h_lo, h_hi = cfg.heights_m
        # Z = fy H / (96 s) for the shortest and the tallest person, within the searched depths
        z_near = max(cam.fy * h_lo / (PERSON_PX * scale), cfg.min_range_m)
        z_far = min(cam.fy * h_hi / (PERSON_PX * scale), cfg.max_range_m)
        if z_near > z_far:
            return None
        x = self.cam_x + np.array([z_near, z_far])
        centre = path.centre_y(x)
        pts = np.array([[x[k], centre[k] + side * cfg.half_width_m, 0.0] for k in (0, 1) for side in (-1, 1)])
        uv, _ = self.rig.project_vehicle_points(pts)
        # feet rows of the nearest and farthest person; the window reaches 112 s px above the feet and 16 s below
        v_top = uv[:, 1].min() - (WINDOW_PX[1] - FEET_MARGIN_PX) * scale
        v_bot = uv[:, 1].max() + FEET_MARGIN_PX * scale
        u0, u1 = uv[:, 0].min() - WINDOW_PX[0] * scale / 2, uv[:, 0].max() + WINDOW_PX[0] * scale / 2
        box = (int(max(np.floor(u0), 0)), int(max(np.floor(v_top), 0)), int(min(np.ceil(u1), cam.width)),
               int(min(np.ceil(v_bot), cam.height)))
        if box[2] - box[0] < WINDOW_PX[0] * scale or box[3] - box[1] < WINDOW_PX[1] * scale:
            return None
        return box

    def search(self, image: np.ndarray, path: EgoPath) -> tuple[list[Detection], SearchStats]:
        cfg = self.cfg
        boxes, scores, windows = [], [], 0
        for s in self.scales:
            region = self._region(float(s), path)
            if region is None:
                continue
            u0, v0, u1, v1 = region
            size = (max(int(round((u1 - u0) / s)), WINDOW_PX[0]), max(int(round((v1 - v0) / s)), WINDOW_PX[1]))
            crop = cv2.resize(image[v0:v1, u0:u1], size, interpolation=cv2.INTER_LINEAR)
            model_scores = self.model.score_map(block_grid(crop))
            windows += model_scores.size
            x, y = np.nonzero(model_scores >= cfg.threshold)
            sx, sy = (u1 - u0) / size[0], (v1 - v0) / size[1]
            boxes.append(np.column_stack([u0 + x * CELL_PX * sx, v0 + y * CELL_PX * sy,
                                          np.full(len(x), WINDOW_PX[0] * sx), np.full(len(x), WINDOW_PX[1] * sy)]))
            scores.append(model_scores[x, y])
        stats = SearchStats(windows, self.full_windows, len(self.scales))
        if not boxes:
            return [], stats
        b = np.round(np.concatenate(boxes)).astype(np.int32)
        return group(b, np.concatenate(scores), cfg.group_threshold), stats
