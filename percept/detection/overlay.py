"""Detections drawn on the image they were found in (``percept detect --out``)."""

from __future__ import annotations

import cv2
import numpy as np

from .pyramid import Detection

BOX_BGR = (60, 220, 60)


def draw_detections(image: np.ndarray, detections: list[Detection], title: str) -> np.ndarray:
    """A BGR copy of ``image`` with each detection's box and score, and ``title`` with the count in the corner."""
    out = cv2.cvtColor(image, cv2.COLOR_GRAY2BGR) if image.ndim == 2 else image.copy()
    for d in detections:
        u0, v0, u1, v1 = (int(round(c)) for c in d.box_px)
        cv2.rectangle(out, (u0, v0), (u1, v1), BOX_BGR, 2, cv2.LINE_AA)
        cv2.putText(out, f"{d.score:.2f}", (u0 + 2, max(v0 - 4, 10)), cv2.FONT_HERSHEY_SIMPLEX, 0.45, BOX_BGR, 1,
                    cv2.LINE_AA)
    label = f"{title}: {len(detections)} person(s)"
    cv2.putText(out, label, (8, 20), cv2.FONT_HERSHEY_SIMPLEX, 0.55, (0, 0, 0), 3, cv2.LINE_AA)
    cv2.putText(out, label, (8, 20), cv2.FONT_HERSHEY_SIMPLEX, 0.55, (255, 255, 255), 1, cv2.LINE_AA)
    return out
