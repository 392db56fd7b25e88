"""The unconstrained search: every window of an image pyramid, for footage without calibration.

Scales 1, 1.05, 1.05^2, ... while the shrunken image still holds a window (as OpenCV's ``detectMultiScale``
builds them); at each scale the image's HOG blocks are computed once (``hog.block_grid``) and every window at an
8-pixel stride is scored from them (``LinearModel.score_map``). Windows scoring at least the threshold are
grouped as ``detectMultiScale`` groups them (``cv2.groupRectangles``: rectangles within 20 % of each other's size
and position form a cluster, clusters of fewer than ``group_threshold + 1`` are dropped, the cluster's mean is
the detection); a detection's score is the best of the windows it was made from. A model with a second stage
(a cascade) keeps a detection only if the second stage takes one of its windows for a person.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from percept.compiled import kernel

from .hog import CELL_PX, WINDOW_PX, LinearModel, block_grid


@dataclass(frozen=True)
class Detection:
    """box_px: (u0, v0, u1, v1) in the image [px]; score: the linear model's margin (0 is the decision boundary);
    windows: how many windows were grouped into it (1: a lone window)."""

    box_px: tuple[float, float, float, float]
    score: float
    windows: int = 1

    def to_dict(self) -> dict:
        return {"box_px": [round(float(c), 1) for c in self.box_px], "score": round(float(self.score), 4)}


def pyramid_scales(width: int, height: int, step: float = 1.05, max_levels: int = 64) -> list[float]:
    """Shrink factors of the pyramid: step^k while the image shrunk by it still holds a window."""
    if not step > 1.0:
        raise ValueError(f"the pyramid's scale step must be > 1, got {step}")
    scales, s = [], 1.0
    while len(scales) < max_levels and round(width / s) >= WINDOW_PX[0] and round(height / s) >= WINDOW_PX[1]:
        scales.append(s)
        s *= step
    return scales


def windows_at_scale(image: np.ndarray, model: LinearModel, scale: float,
                     threshold: float) -> tuple[np.ndarray, np.ndarray]:
    """Windows of ``image`` shrunk by ``scale`` that score >= ``threshold``: boxes (N, 4) as (x, y, w, h) in the
    original image [px] and their scores (N,)."""
    boxes, scores, _ = _windows_at_scale(image, model, scale, threshold)
    return boxes, scores


def _windows_at_scale(image: np.ndarray, model: LinearModel, scale: float,
                      threshold: float) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """``windows_at_scale`` and the windows' second-stage scores (N,) (None without a second stage)."""
    h, w = image.shape[:2]
    size = (round(w / scale), round(h / scale))
    small = image if size == (w, h) else cv2.resize(image, size, interpolation=cv2.INTER_LINEAR_EXACT)
    blocks = block_grid(small)
    s = model.score_map(blocks)
    x, y = np.nonzero(s >= threshold)
    win_w, win_h = round(WINDOW_PX[0] * scale), round(WINDOW_PX[1] * scale)
    boxes = np.column_stack([np.round(x * CELL_PX * scale), np.round(y * CELL_PX * scale), np.full(len(x), win_w),
                             np.full(len(x), win_h)])
    return boxes.astype(np.int32), s[x, y], model.second_scores(blocks, x, y)


def group(boxes: np.ndarray, scores: np.ndarray, group_threshold: int = 2, eps: float = 0.2) -> list[Detection]:
    """Clusters of windows (x, y, w, h) -> detections, as ``detectMultiScale`` groups them; each detection's score is
    the best of the windows overlapping it by IoU >= 0.5."""
    if not len(boxes):
        return []
    grouped, weights = cv2.groupRectangles(boxes.tolist(), group_threshold, eps)
    out = []
    for (gx, gy, gw, gh), n in zip(np.asarray(grouped).reshape(-1, 4), np.asarray(weights).ravel()):
        best = _best_of_overlapping((gx, gy, gw, gh), boxes, scores)
        out.append(Detection((float(gx), float(gy), float(gx + gw), float(gy + gh)), best, int(n)))
    return sorted(out, key=lambda d: -d.score)


def _best_of_overlapping(box, boxes: np.ndarray, values: np.ndarray) -> float:
    """The best of ``values`` (N,) over the windows ``boxes`` (N, 4) as (x, y, w, h) that overlap ``box`` (x, y, w, h)
    by IoU >= 0.5 (over every window when none does)."""
    if not len(values):
        return float(values.max())  # numpy's error for the best of nothing
    gx, gy, gw, gh = box
    return float(_best_overlapping(gx, gy, gw, gh, boxes, values))


@kernel()
def _best_overlapping(gx, gy, gw, gh, boxes, values):  # pragma: no cover - compiled
    """``_best_of_overlapping`` in one pass, in numpy's arithmetic: whole-pixel boxes' sides and areas in integers
    (int32 in numpy, no box comes near its limits), the IoU as the float64 quotient; the maxima take a NaN as
    numpy's do."""
    found = False
    best = top = values[0]
    for i in range(boxes.shape[0]):
        # |A n B| = max(min(x_A + w_A, x_B + w_B) - max(x_A, x_B), 0) max(the same along y, 0)
        ix = max(min(gx + gw, boxes[i, 0] + boxes[i, 2]) - max(gx, boxes[i, 0]), 0)
        iy = max(min(gy + gh, boxes[i, 1] + boxes[i, 3]) - max(gy, boxes[i, 1]), 0)
        inter = ix * iy
        # IoU = |A n B| / (|A| + |B| - |A n B|)
        iou = inter / (gw * gh + boxes[i, 2] * boxes[i, 3] - inter)
        v = values[i]
        if np.isnan(v) or v > top:
            top = v
        if iou >= 0.5:
            if not found or np.isnan(v) or v > best:
                best = v
            found = True
    return best if found else top


def second_stage_kept(dets: list[Detection], boxes: np.ndarray, second: np.ndarray | None,
                      threshold: float) -> list[Detection]:
    """The detections that a cascade's second stage keeps: those with a window (of ``boxes`` (N, 4) as (x, y, w, h),
    IoU >= 0.5 with the detection, as its score is found) whose second-stage score ``second`` (N,) is at least
    ``threshold``. A vehicle's corner makes a cluster of windows that all look alike to the second stage; a person
    needs one window that it takes for a person (a per-window veto thins the person's cluster and loses it)."""
    if second is None:
        return dets
    return [d for d in dets if _best_of_overlapping((d.box_px[0], d.box_px[1], d.box_px[2] - d.box_px[0],
                                                     d.box_px[3] - d.box_px[1]), boxes, second) >= threshold]


def lone_windows(boxes: np.ndarray, scores: np.ndarray, eps: float = 0.2) -> list[Detection]:
    """The windows (x, y, w, h) that ``group`` can never keep: those like no other window, by OpenCV's
    ``SimilarRects`` (corners within delta = eps (min(w1, w2) + min(h1, h2)) / 2 of each other's), best first."""
    if not len(boxes):
        return []
    b = boxes.astype(np.float64)
    out = [Detection((float(b[i, 0]), float(b[i, 1]), float(b[i, 0] + b[i, 2]), float(b[i, 1] + b[i, 3])),
                     float(scores[i])) for i in np.flatnonzero(_lone(b, float(eps)))]
    return sorted(out, key=lambda d: -d.score)


@kernel()
def _lone(b, eps):  # pragma: no cover - compiled
    """(N,) bool: whether each window of ``b`` (N, 4) float64 (x, y, w, h) is similar to none but itself."""
    n = b.shape[0]
    lone = np.empty(n, np.bool_)
    for i in range(n):
        similar = 0
        for j in range(n):
            # delta = eps (min(w_i, w_j) + min(h_i, h_j)) / 2
            delta = eps * (min(b[i, 2], b[j, 2]) + min(b[i, 3], b[j, 3])) / 2
            similar += (abs(b[i, 0] - b[j, 0]) <= delta and abs(b[i, 1] - b[j, 1]) <= delta
                        and abs((b[i, 0] + b[i, 2]) - (b[j, 0] + b[j, 2])) <= delta
                        and abs((b[i, 1] + b[i, 3]) - (b[j, 1] + b[j, 3])) <= delta)
        lone[i] = similar == 1
    return lone


def detect_multiscale(image: np.ndarray, model: LinearModel, step: float = 1.05, threshold: float = 0.0,
                      group_threshold: int = 2) -> list[Detection]:
    """People in ``image`` (grey or BGR uint8) at every scale of the pyramid, best first."""
    h, w = image.shape[:2]
    if w < WINDOW_PX[0] or h < WINDOW_PX[1]:
        raise ValueError(f"image of {w}x{h} px is smaller than the {WINDOW_PX[0]}x{WINDOW_PX[1]} detection window")
    found = [_windows_at_scale(image, model, s, threshold) for s in pyramid_scales(w, h, step)]
    boxes = np.concatenate([f[0] for f in found])
    scores = np.concatenate([f[1] for f in found])
    second = None if model.second is None else np.concatenate([f[2] for f in found])
    return second_stage_kept(group(boxes, scores, group_threshold), boxes, second, model.second_threshold)
