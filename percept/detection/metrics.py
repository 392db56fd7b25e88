"""Scoring formulas for pedestrian detection: IoU, greedy matching with ignore regions, rates.

docs/design.md, "Scoring definitions": a detection matches a ground-truth box of a pedestrian at least half
visible and at least 24 px tall when IoU >= 0.5; recall, precision, false positives per image.
Boxes are (u0, v0, u1, v1) in pixels, u = column, v = row, u0 <= u1 and v0 <= v1.

Matching follows the PASCAL VOC rule (Everingham et al. 2010, "The PASCAL Visual Object Classes
(VOC) Challenge", IJCV) with the ignore regions of the Caltech pedestrian benchmark (Dollár et
al. 2012, "Pedestrian Detection: An Evaluation of the State of the Art", PAMI): ground truth
that is not eligible (too small, mostly hidden) neither earns nor costs anything.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from percept.sensors.boxes import check_boxes as _boxes
from percept.sensors.boxes import iou_matrix


def eligible(box_px: np.ndarray, visible: float, min_height_px: float = 24.0, min_visible: float = 0.5) -> bool:
    """True when a ground-truth pedestrian counts: visible fraction >= min_visible, height >= min_height_px."""
    box = _boxes(np.reshape(box_px, (1, -1)), "eligible")[0]
    if not 0.0 <= visible <= 1.0:
        raise ValueError(f"visible is the visible fraction in [0, 1], got {visible!r}")
    # h = v1 - v0
    return bool(box[3] - box[1] >= min_height_px and visible >= min_visible)


@dataclass(frozen=True)
class FrameMatch:
    """Outcome of matching one frame's detections to its ground truth.

    tp, fp, fn: counts; ignored: detections absorbed by an ignore region (neither tp nor fp);
    pairs: (detection index, ground-truth index) of the true positives, in matching order.
    """

    tp: int
    fp: int
    fn: int
    ignored: int = 0
    pairs: tuple[tuple[int, int], ...] = ()


def match_detections(det_boxes: np.ndarray, det_scores: np.ndarray, gt_boxes: np.ndarray,
                     gt_eligible: np.ndarray, iou_min: float = 0.5) -> FrameMatch:
    """Greedy matching by descending detection score, each eligible ground-truth box at most once.

    A detection's candidates are the still unmatched eligible boxes and all ignore boxes
    (``gt_eligible`` False) with IoU >= iou_min; it takes the one of highest IoU (an eligible
    box on a tie). Matched to an eligible box: true positive. Matched to an ignore box: neither
    true nor false positive (an ignore box may absorb several). No candidate: false positive.
    Eligible boxes left unmatched are misses; ignore boxes never are.
    """
    det = _boxes(det_boxes, "detections")
    gt = _boxes(gt_boxes, "ground truth")
    scores = np.asarray(det_scores, dtype=np.float64).reshape(-1)
    keep_gt = np.asarray(gt_eligible, dtype=bool).reshape(-1)
    if scores.size != len(det) or keep_gt.size != len(gt):
        raise ValueError(f"{len(det)} detection boxes with {scores.size} scores, {len(gt)} ground-truth boxes "
                         f"with {keep_gt.size} eligibility flags: give one per box")
    if not np.all(np.isfinite(scores)):
        raise ValueError("detection scores must be finite")
    if not (0.0 < iou_min <= 1.0):
        raise ValueError(f"iou_min must be in (0, 1], got {iou_min!r}")
    overlap = iou_matrix(det, gt)
    taken = np.zeros(len(gt), dtype=bool)
    pairs: list[tuple[int, int]] = []
    fp = ignored = 0
    for d in np.argsort(-scores, kind="stable"):
        # an eligible box already taken is no candidate; ignore boxes always are
        cand = np.where((overlap[d] >= iou_min) & ~(keep_gt & taken), overlap[d], -1.0)
        # highest IoU first, an eligible box first on a tie
        best = int(np.lexsort((~keep_gt, -cand))[0]) if len(gt) else -1
        if best < 0 or cand[best] < 0.0:
            fp += 1
        elif keep_gt[best]:
            taken[best] = True
            pairs.append((int(d), best))
        else:
            ignored += 1
    fn = int(np.count_nonzero(keep_gt & ~taken))
    return FrameMatch(tp=len(pairs), fp=fp, fn=fn, ignored=ignored, pairs=tuple(pairs))


@dataclass(frozen=True)
class DetectionScore:
    """Totals over frames; the rates are None when their denominator is 0."""

    tp: int
    fp: int
    fn: int
    frames: int

    @property
    def recall(self) -> float | None:
        # recall = TP / (TP + FN)
        return self.tp / (self.tp + self.fn) if self.tp + self.fn else None

    @property
    def precision(self) -> float | None:
        # precision = TP / (TP + FP)
        return self.tp / (self.tp + self.fp) if self.tp + self.fp else None

    @property
    def fppi(self) -> float | None:
        # FPPI = sum FP / number of images
        return self.fp / self.frames if self.frames else None


def score_frames(matches: list[FrameMatch]) -> dict:
    """Recall, precision and false positives per image over frames, with the totals behind them."""
    s = DetectionScore(tp=sum(m.tp for m in matches), fp=sum(m.fp for m in matches),
                       fn=sum(m.fn for m in matches), frames=len(matches))
    return {"recall": s.recall, "precision": s.precision, "fppi": s.fppi,
            "tp": s.tp, "fp": s.fp, "fn": s.fn, "frames": s.frames}


HEIGHT_BINS_PX = ((24.0, 40.0, "24-40"), (40.0, float("inf"), ">=40"))
"""Ground-truth height bins [px] for recall: the far field and the rest."""


class DetectionTally:
    """Per-frame matching accumulated over a run: totals for recall / precision / FPPI and recall per height bin
    (``HEIGHT_BINS_PX``), and the range at which each object was first matched."""

    def __init__(self) -> None:
        self.matches: list[FrameMatch] = []
        self.bin_hits = {name: [0, 0] for _, _, name in HEIGHT_BINS_PX}
        self.first_range_m: dict = {}

    def add(self, det_boxes, det_scores, gt_boxes, gt_eligible, gt_ids=(), gt_range_m=()) -> FrameMatch:
        """One frame: detections against ground truth (ineligible boxes are ignore regions); ``gt_ids`` and
        ``gt_range_m`` (optional, one per box) record first-detection ranges."""
        gt = np.asarray(gt_boxes, dtype=np.float64).reshape(-1, 4)
        keep = np.asarray(gt_eligible, dtype=bool).reshape(-1)
        m = match_detections(np.asarray(det_boxes, dtype=np.float64).reshape(-1, 4), det_scores, gt, keep)
        self.matches.append(m)
        hit = {g for _, g in m.pairs}
        for g in np.flatnonzero(keep):
            h = gt[g, 3] - gt[g, 1]
            for lo, hi, name in HEIGHT_BINS_PX:
                if lo <= h < hi:
                    self.bin_hits[name][0] += int(g in hit)
                    self.bin_hits[name][1] += 1
        for g in hit:
            if len(gt_ids) and gt_ids[g] not in self.first_range_m:
                self.first_range_m[gt_ids[g]] = float(gt_range_m[g])
        return m

    def result(self) -> dict:
        """score_frames' keys plus ``recall_by_height`` {bin: recall or None}, ``matched_by_height`` {bin: [matched,
        eligible]} (counts, for pooling runs) and ``first_detection_range_m`` (the median over objects of the range
        of their first match, None when none was matched)."""
        out = score_frames(self.matches)
        out["recall_by_height"] = {k: (h / n if n else None) for k, (h, n) in self.bin_hits.items()}
        out["matched_by_height"] = {k: [h, n] for k, (h, n) in self.bin_hits.items()}
        first = list(self.first_range_m.values())
        out["first_detection_range_m"] = float(np.median(first)) if first else None
        return out
