"""The horizon and pitch of recorded footage from the lane lines' vanishing point."""

import math

import cv2
import numpy as np
import pytest

from percept.lanes.horizon import estimate_vanishing_point, make_rig
from percept.sensors import PinholeCamera


def test_vanishing_point_of_a_synthetic_road():
    """Two painted lines, parallel on the ground, seen by a camera pitched 2 deg down: the estimated horizon gives
    the pitch back within 0.2 deg."""
    cam = PinholeCamera.from_hfov(960, 540, math.radians(60))
    rig = make_rig(cam, cam.cy - cam.fy * math.tan(math.radians(2.0)), 1.2)
    img = np.full((540, 960, 3), 70, np.uint8)
    H = rig.ground_homography()
    for y0 in (1.8, -1.9):
        quad = np.array([[4.0, y0], [60.0, y0], [60.0, y0 + 0.15], [4.0, y0 + 0.15]])
        p = np.column_stack([quad, np.ones(4)]) @ H.T
        cv2.fillPoly(img, [np.round(p[:, :2] / p[:, 2:]).astype(np.int32)], (235, 235, 235))
    vp = estimate_vanishing_point(img, bottom_margin_frac=0.0)
    assert vp is not None
    pitch = make_rig(cam, vp.v, 1.2).pitch_rad
    assert math.degrees(pitch) == pytest.approx(2.0, abs=0.2)
    assert vp.u == pytest.approx(cam.cx, abs=3)
