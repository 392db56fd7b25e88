"""The rendered stereo pair is geometrically exact and matchable: fronto-parallel surfaces shift by f·b/Z
between the two images, and OpenCV's semi-global matcher recovers the ground-truth depth."""

import cv2
import numpy as np
import pytest

from percept.sensors import Pose2D, StereoRig
from percept.sims.render import ObjectKind, ObjectState, Scene, StereoRenderer

EGO = Pose2D(100.0, -4.0, 0.0)
"""Ego in lane 1 of highway-env's straight 4-lane road (world y = -4), looking along +x."""
SEED = 3


def car(oid: int, x_m: float, y_m: float = EGO.y_m, style: int = 1, yaw: float = 0.0) -> ObjectState:
    return ObjectState(oid, ObjectKind.VEHICLE, Pose2D(x_m, y_m, yaw), 4.8, 1.9, 1.5, style=style)


def _subpixel_peak(scores: np.ndarray) -> float:
    """Column of the maximum of a 1-D score row, refined by a parabola through the peak and its neighbours."""
    k = int(np.argmax(scores))
    if 0 < k < len(scores) - 1:
        a, b, c = scores[k - 1], scores[k], scores[k + 1]
        # vertex of the parabola through (-1, a), (0, b), (1, c)
        return k + 0.5 * (a - c) / (a - 2 * b + c)
    return float(k)


@pytest.mark.parametrize("ahead_m", [8.0, 15.0, 30.0])
def test_rear_face_shifts_by_disparity(rig, road, ahead_m):
    r = StereoRenderer(rig, road, seed=SEED, scenery=False)
    obj = car(5, EGO.x_m + ahead_m)
    out = r.render(Scene(EGO, (obj,)))
    z = obj.pose.x_m - obj.length_m / 2 - EGO.x_m - rig.mount_x_m
    face = (out.ids == 5) & (np.abs(out.depth_m - z) < 0.015)
    inner = cv2.erode(face.astype(np.uint8), np.ones((5, 5), np.uint8)).astype(bool)
    # the depth map on the face is the face's depth (decals sit 1 cm proud)
    assert np.all((np.abs(out.depth_m[inner] - z) < 1e-4 * z) | (np.abs(out.depth_m[inner] - (z - 0.01)) < 1e-4 * z))
    # template: the face's interior in the left image; search along the same rows of the right image
    rows, cols = np.nonzero(inner)
    v0, v1, u0, u1 = rows.min(), rows.max() + 1, cols.min(), cols.max() + 1
    left = cv2.cvtColor(out.left, cv2.COLOR_BGR2GRAY).astype(np.float32)
    right = cv2.cvtColor(out.right, cv2.COLOR_BGR2GRAY).astype(np.float32)
    d_true = float(rig.disparity_px(z))
    lo = max(int(u0 - d_true) - 8, 0)
    scores = cv2.matchTemplate(right[v0:v1, lo:u1], left[v0:v1, u0:u1], cv2.TM_CCOEFF_NORMED)[0]
    d = u0 - (lo + _subpixel_peak(scores))
    assert scores.max() > 0.98
    assert d == pytest.approx(d_true, abs=0.5)


def test_sgbm_recovers_depth_on_a_highway(rig, road):
    """Texture is matchable: SGBM depth within 5 % of the truth on >= 80 % of valid pixels nearer than 40 m."""
    r = StereoRenderer(rig, road, seed=SEED, scenery=True)
    cars = (car(1, EGO.x_m + 14.0, style=1), car(2, EGO.x_m + 24.0, EGO.y_m - 4.0, style=2),
            car(3, EGO.x_m + 33.0, EGO.y_m + 4.0, style=4), car(4, EGO.x_m + 9.0, EGO.y_m - 4.0, style=6),
            car(5, EGO.x_m + 55.0, EGO.y_m, style=7))
    out = r.render(Scene(EGO, cars))
    frac, n = sgbm_fraction(rig, out)
    assert n > 20000
    assert frac >= 0.8, f"SGBM depth within 5% on {frac:.1%} of {n} valid pixels"


def sgbm_fraction(rig: StereoRig, out) -> tuple[float, int]:
    """Fraction of valid pixels (SGBM disparity > 0, true depth finite and < 40 m) whose SGBM depth
    f b / d is within 5 % of the truth, and the number of valid pixels."""
    block = 5
    sgbm = cv2.StereoSGBM_create(minDisparity=0, numDisparities=128, blockSize=block, P1=8 * 3 * block ** 2,
                                 P2=32 * 3 * block ** 2, disp12MaxDiff=1, uniquenessRatio=10, speckleWindowSize=100,
                                 speckleRange=2, mode=cv2.STEREO_SGBM_MODE_SGBM_3WAY)
    disp = sgbm.compute(out.left, out.right).astype(np.float32) / 16.0
    gt = out.depth_m
    valid = (disp > 0) & np.isfinite(gt) & (gt < 40.0)
    # depth from disparity: Z = f b / d
    est = rig.camera.fx * rig.baseline_m / disp[valid]
    ok = np.abs(est - gt[valid]) / gt[valid] < 0.05
    return float(ok.mean()), int(valid.sum())
