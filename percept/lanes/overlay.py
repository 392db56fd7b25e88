"""Overlay of a lane result on the camera image: both boundaries, the lane area, the evidence and the values.

Boundaries are projected from the vehicle frame with the rig (see ``realworld.boundary_points_px``); the
evidence dots are the top-hat stripe centres (green: fitted left, magenta: fitted right, grey: outliers); a red
frame marks each vehicle whose evidence was dropped (its shade's width, 1.5 m tall at its range).
"""

from __future__ import annotations

import math

import cv2
import numpy as np

from .realworld import LaneResult

LEFT_BGR = (0, 220, 255)  # yellow-orange
RIGHT_BGR = (255, 160, 0)  # blue
TEXT_BGR = (255, 255, 255)
VEHICLE_BGR = (0, 0, 255)


def _text_block(img: np.ndarray, lines: list[str], scale: float) -> np.ndarray:
    """White lines of text on a half-transparent dark box in the top-left corner."""
    font, fs, th = cv2.FONT_HERSHEY_SIMPLEX, 0.8 * scale, max(1, int(round(2 * scale)))
    sizes = [cv2.getTextSize(t, font, fs, th)[0] for t in lines]
    step = int(max(h for _, h in sizes) * 1.8) + 2
    pad = int(10 * scale) + 2
    box = img.copy()
    cv2.rectangle(box, (0, 0), (max(w for w, _ in sizes) + 2 * pad, step * len(lines) + pad), (0, 0, 0), -1)
    img = cv2.addWeighted(box, 0.5, img, 0.5, 0)
    for i, t in enumerate(lines):
        cv2.putText(img, t, (pad, pad + step * i + sizes[i][1]), font, fs, TEXT_BGR, th, cv2.LINE_AA)
    return img


def draw_overlay(image: np.ndarray, result: LaneResult, label: str = "", evidence: bool = True) -> np.ndarray:
    """A copy of ``image`` (BGR, the rig's size) with the lane drawn on it and the values written in the top-left
    corner: offset [m], heading [deg], curvature [1/m] (and radius [m]), width [m], confidence."""
    out = image.copy()
    h, w = out.shape[:2]
    scale = max(w / 1280.0, 0.4)
    lw = max(2, int(round(3 * scale)))
    e = result.estimate
    hz = int(round(result.rig.horizon_row))
    if 0 <= hz < h:
        # the horizon the geometry uses, dashed
        for u in range(0, w, 24):
            cv2.line(out, (u, hz), (min(u + 12, w - 1), hz), (200, 200, 200), 1, cv2.LINE_AA)
    ev = result.debug.evidence
    fit = result.debug.fit
    for box in () if ev is None else ev.vehicles:
        tall = int(round(result.rig.camera.fx * 1.5 / box.range_m))
        cv2.rectangle(out, (box.u0_px, box.bottom_px - tall), (box.u1_px - 1, box.bottom_px), VEHICLE_BGR,
                      max(1, lw // 2), cv2.LINE_AA)
    if evidence and ev is not None and len(ev.uv_px):
        side = fit.side if fit is not None else np.zeros(len(ev.uv_px), int)
        colours = {1: (0, 255, 0), -1: (255, 0, 255), 0: (160, 160, 160)}
        for (u, v), s in zip(np.round(ev.uv_px).astype(int), side):
            cv2.circle(out, (int(u), int(v)), 1, colours[int(s)], -1)
    if e.valid and all(len(p) >= 2 for p in result.boundaries_px.values()):
        left, right = result.boundaries_px["left"], result.boundaries_px["right"]
        poly = np.vstack([left, right[::-1]]).round().astype(np.int32)
        fill = out.copy()
        cv2.fillPoly(fill, [poly], (0, 180, 0))
        out = cv2.addWeighted(fill, 0.25, out, 0.75, 0)
        for pts, col in ((left, LEFT_BGR), (right, RIGHT_BGR)):
            cv2.polylines(out, [pts.round().astype(np.int32)], False, col, lw, cv2.LINE_AA)
    lines = [label] if label else []
    if e.valid:
        radius = "inf" if abs(e.curvature_1pm) < 1e-5 else f"{1.0 / e.curvature_1pm:+.0f} m"
        lines += [f"offset {result.offset_m:+.2f} m   heading {math.degrees(e.heading_rad):+.2f} deg",
                  f"curvature {e.curvature_1pm:+.5f} 1/m (R {radius})",
                  f"width {e.width_m:.2f} m   confidence {e.confidence:.2f}"]
    else:
        lines.append("no lane found")
    return _text_block(out, lines, scale)
