"""The peers: the stock way to do each stage's job, timed in the same run as percept's own stage (``percept bench``).

Each peer factory takes the frames it will run on and returns (its name as the tables print it, ``run(frame)``).
"""

from __future__ import annotations

from typing import Callable

import cv2
import numpy as np


def topdown_ready(world):
    """``world`` with highway-env's own top-down ``render()`` set to the camera's size (the render's peer)."""
    world.env.render_mode = "rgb_array"
    world.env.config.update(screen_width=world.cfg.rig.camera.width, screen_height=world.cfg.rig.camera.height)
    return world


def lane_fit_full_frame(frames: list) -> tuple[str, Callable]:
    """The stock lane fit: grey, Gaussian blur, Canny, a trapezoid mask below the horizon, ``HoughLinesP``, and a
    least-squares line through each side's segments (left: negative slope)."""
    h, w = frames[0].left.shape[:2]
    mask = np.zeros((h, w), np.uint8)
    cv2.fillPoly(mask, [np.array([[0, h], [int(0.45 * w), int(0.55 * h)], [int(0.55 * w), int(0.55 * h)], [w, h]],
                                 np.int32)], 255)

    def run(frame) -> None:
        edges = cv2.Canny(cv2.GaussianBlur(cv2.cvtColor(frame.left, cv2.COLOR_BGR2GRAY), (5, 5), 0), 50, 150)
        segs = cv2.HoughLinesP(edges & mask, 2, np.pi / 180, 20, minLineLength=20, maxLineGap=60)
        if segs is None:
            return
        s = segs.reshape(-1, 4).astype(np.float64)
        slope = (s[:, 3] - s[:, 1]) / np.maximum(np.abs(s[:, 2] - s[:, 0]), 1e-6) * np.sign(s[:, 2] - s[:, 0])
        for side in (slope < -0.3, slope > 0.3):
            if side.sum() >= 1:
                # u = a v + b through both ends of the side's segments
                np.polyfit(np.r_[s[side, 1], s[side, 3]], np.r_[s[side, 0], s[side, 2]], 1)
    return "Canny + HoughLinesP + a line per side, full frame", run


def sgbm_full_frame(frames: list) -> tuple[str, Callable]:
    """The stock way to range what is ahead: OpenCV's StereoSGBM over the whole grey frame (96 disparities, 5x5
    blocks, the usual P1 = 8 c b^2, P2 = 32 c b^2 smoothness penalties)."""
    from percept.longitudinal.dense import sample_sgbm

    sgbm = sample_sgbm(96, 5)

    def run(frame) -> None:
        sgbm.compute(cv2.cvtColor(frame.left, cv2.COLOR_BGR2GRAY), cv2.cvtColor(frame.right, cv2.COLOR_BGR2GRAY))
    return "OpenCV StereoSGBM, full frame", run


def people_detector_full_frame(frames: list) -> tuple[str, Callable]:
    """The stock way to find people: OpenCV's HOG ``detectMultiScale`` with its default (INRIA) people detector
    over the whole frame (8-pixel stride, 8-pixel padding, scale step 1.05)."""
    hog = cv2.HOGDescriptor()
    hog.setSVMDetector(cv2.HOGDescriptor_getDefaultPeopleDetector())

    def run(frame) -> None:
        hog.detectMultiScale(frame.left, winStride=(8, 8), padding=(8, 8), scale=1.05)
    return "OpenCV HOG detectMultiScale (default people detector), full frame", run


def sgbm_both_rigs(frames: list) -> tuple[str, Callable]:
    """The stock way to see the vehicles all round: OpenCV's StereoSGBM (as ``sgbm_full_frame``) over both full
    frames of the forward rig and, where the frame has one, of the rear rig."""
    name, forward = sgbm_full_frame(frames)
    from percept.longitudinal.dense import sample_sgbm

    sgbm = sample_sgbm(96, 5)

    def run(frame) -> None:
        forward(frame)
        if frame.has_rear:
            sgbm.compute(cv2.cvtColor(frame.rear_left, cv2.COLOR_BGR2GRAY),
                         cv2.cvtColor(frame.rear_right, cv2.COLOR_BGR2GRAY))
    return "OpenCV StereoSGBM, full frames of both rigs", run
