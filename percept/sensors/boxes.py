"""Image boxes (u0, v0, u1, v1) in pixels, u = column, v = row, u0 <= u1 and v0 <= v1: checks and overlap."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["check_boxes", "iou", "iou_matrix"]


def check_boxes(boxes: np.ndarray, what: str) -> np.ndarray:
    """Validated (K, 4) float boxes; an empty input is (0, 4)."""
    b = np.asarray(boxes, dtype=np.float64)
    if b.size == 0:
        return b.reshape(0, 4)
    if b.ndim != 2 or b.shape[1] != 4:
        raise ValueError(f"{what}: expected boxes of shape (K, 4) as (u0, v0, u1, v1), got {b.shape}")
    if not np.all(np.isfinite(b)):
        raise ValueError(f"{what}: box coordinates must be finite")
    if np.any(b[:, 2] < b[:, 0]) or np.any(b[:, 3] < b[:, 1]):
        raise ValueError(f"{what}: a box has u1 < u0 or v1 < v0; boxes are (u0, v0, u1, v1)")
    return b


def iou_matrix(a_boxes: np.ndarray, b_boxes: np.ndarray) -> np.ndarray:
    """Intersection over union of every box of A (N, 4) with every box of B (M, 4) -> (N, M).

    Two boxes of zero area have IoU 0.
    """
    a = check_boxes(a_boxes, "iou_matrix A")[:, None, :]
    b = check_boxes(b_boxes, "iou_matrix B")[None, :, :]
    # |A ∩ B| = max(0, min(u1) - max(u0)) * max(0, min(v1) - max(v0))
    inter_w = np.clip(np.minimum(a[..., 2], b[..., 2]) - np.maximum(a[..., 0], b[..., 0]), 0.0, None)
    inter_h = np.clip(np.minimum(a[..., 3], b[..., 3]) - np.maximum(a[..., 1], b[..., 1]), 0.0, None)
    inter = inter_w * inter_h
    area_a = (a[..., 2] - a[..., 0]) * (a[..., 3] - a[..., 1])
    area_b = (b[..., 2] - b[..., 0]) * (b[..., 3] - b[..., 1])
    # |A ∪ B| = |A| + |B| - |A ∩ B|
    union = area_a + area_b - inter
    # IoU = |A ∩ B| / |A ∪ B|
    return np.divide(inter, union, out=np.zeros_like(inter), where=union > 0.0)


def iou(a, b) -> float:
    """Intersection over union of two boxes (u0, v0, u1, v1) [px]: ``iou_matrix``'s arithmetic for one pair, in Python
    floats (the same IEEE doubles, so the same value) rather than (1, 1) arrays, whose checks and ufuncs cost many
    times more."""
    (au0, av0, au1, av1), (bu0, bv0, bu1, bv1) = _one_box(a, "iou A"), _one_box(b, "iou B")
    # |A ∩ B| = max(0, min(u1) - max(u0)) * max(0, min(v1) - max(v0))
    w, h = min(au1, bu1) - max(au0, bu0), min(av1, bv1) - max(av0, bv0)
    inter = (w if w > 0.0 else 0.0) * (h if h > 0.0 else 0.0)
    # |A ∪ B| = |A| + |B| - |A ∩ B|
    union = (au1 - au0) * (av1 - av0) + (bu1 - bu0) * (bv1 - bv0) - inter
    # IoU = |A ∩ B| / |A ∪ B|, 0 for two boxes of zero area
    return inter / union if union > 0.0 else 0.0


def _one_box(box, what: str) -> tuple[float, float, float, float]:
    """A box's four coordinates as floats, checked as ``check_boxes`` checks them (a tuple or list of four numbers
    directly, anything else through it)."""
    if isinstance(box, (tuple, list)) and len(box) == 4:
        c = tuple(float(x) for x in box)
        if not all(math.isfinite(x) for x in c):
            raise ValueError(f"{what}: box coordinates must be finite")
        if c[2] < c[0] or c[3] < c[1]:
            raise ValueError(f"{what}: a box has u1 < u0 or v1 < v0; boxes are (u0, v0, u1, v1)")
        return c
    return tuple(check_boxes(np.reshape(box, (1, -1)), what)[0].tolist())
