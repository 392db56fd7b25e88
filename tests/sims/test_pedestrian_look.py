"""Rendered pedestrians look like people to OpenCV's pretrained INRIA people detector, and stand on the road.

Protocol (from the issue): cv2.HOGDescriptor with the default people detector, ``detectMultiScale(left,
winStride=(8, 8), padding=(8, 8), scale=1.05)``, default hit threshold (0) and grouping. The ground
truth is the pedestrian's tight silhouette box grown to the detector's convention: a 1:2 window in
which the person fills the middle 3/4 of the height. A pedestrian counts as found when a detection
overlaps that window with IoU >= 0.5. Pedestrians 100-250 px tall must be found at least 90% of the time.
"""

from __future__ import annotations

import math

import cv2
import numpy as np
import numpy.testing as npt
import pytest
from highway_env.road.road import RoadNetwork

from percept.sensors import Pose2D, Side, StereoRig
from percept.sims.render import ObjectKind, ObjectState, Scene, StereoRenderer
from percept.sims.render.raster import OUTLINES
from percept.sims.road_geometry import build_road_geometry

EPS = np.finfo(np.float64).eps
SLOTS_U = (110.0, 320.0, 530.0)
"""Image columns [px] of the three pedestrians in a frame: far enough apart that their windows never overlap."""


@pytest.fixture(scope="module")
def road():
    return build_road_geometry(RoadNetwork.straight_road_network(4, length=2000))


def _place(ego: Pose2D, rig: StereoRig, u: float, height_m: float, target_px: float) -> tuple[float, float]:
    """World (x, y) [m] of a person ``height_m`` tall who appears ``target_px`` tall at image column ``u``."""
    cam = rig.camera
    z = cam.fx * height_m / target_px  # camera depth [m]: h_px = f h / Z
    # left camera at y_v = +b/2; image column u -> lateral offset y_v = b/2 - (u - cx) Z / fx
    y_v = rig.baseline_m / 2 - (u - cam.cx) * z / cam.fx
    x_v = rig.mount_x_m + z
    c, s = math.cos(ego.yaw_rad), math.sin(ego.yaw_rad)
    return ego.x_m + c * x_v - s * y_v, ego.y_m + s * x_v + c * y_v


def crossing_frames(rig: StereoRig, n_frames: int = 10) -> list[Scene]:
    """Deterministic `crossing`-like frames: three pedestrians each, 105-240 px tall, spread over the kinds
    (crossing from the left, crossing from the right, walking along the road, standing), heights
    1.5-1.95 m, gait phases, clothing styles and distances; a car ahead in some frames."""
    frames = []
    for k in range(n_frames):
        ego = Pose2D(100.0 + 41.0 * k, -6.0, 0.0)
        objs = []
        for j, u in enumerate(SLOTS_U):
            i = 3 * k + j
            kind = (i + k) % 4
            h = 1.5 + 0.45 * ((7 * i) % 10) / 9
            px = 105.0 + 135.0 * ((3 * i + k) % 10) / 9
            x, y = _place(ego, rig, u, h, px)
            jitter = 0.1 * math.sin(3.7 * i)
            if kind == 0:
                yaw, speed = math.pi / 2 + jitter, 1.4  # crossing from the right (walking to the left)
            elif kind == 1:
                yaw, speed = -math.pi / 2 + jitter, 1.4  # crossing from the left
            elif kind == 2:
                yaw, speed = (0.0 if i % 2 else math.pi) + jitter, 1.2  # along the road, back or front view
            else:
                yaw, speed = 2.3 * i % (2 * math.pi) - math.pi, 0.0  # standing, any direction
            objs.append(ObjectState(i + 1, ObjectKind.PEDESTRIAN, Pose2D(x, y, yaw), 0.5, 0.5, h, style=13 * i + 5,
                                    speed_mps=speed, gait_phase=(0.618 * i % 1.0) * 2 * math.pi))
        if k % 3 == 0:
            car = Pose2D(ego.x_m + 35.0 + 4 * k, -4.0 - 4.0 * (k % 2), 0.0)
            objs.append(ObjectState(100 + k, ObjectKind.VEHICLE, car, 4.5, 1.8, 1.5, style=k))
        frames.append(Scene(ego, tuple(objs)))
    return frames


def detector_window(box) -> tuple[float, float, float, float]:
    """Tight (u0, v0, u1, v1) box -> the detector's 1:2 window in which the person fills the middle 3/4."""
    u0, v0, u1, v1 = box
    height = (v1 - v0) / 0.75
    cu, cv = (u0 + u1) / 2, (v0 + v1) / 2
    return cu - height / 4, cv - height / 2, cu + height / 4, cv + height / 2


def iou(a, b) -> float:
    iw = max(0.0, min(a[2], b[2]) - max(a[0], b[0]))
    ih = max(0.0, min(a[3], b[3]) - max(a[1], b[1]))
    inter = iw * ih
    return inter / ((a[2] - a[0]) * (a[3] - a[1]) + (b[2] - b[0]) * (b[3] - b[1]) - inter)


@pytest.mark.slow
def test_inria_people_detector_finds_rendered_pedestrians(road):
    rig = StereoRig()
    renderer = StereoRenderer(rig, road, seed=0)
    hog = cv2.HOGDescriptor()
    hog.setSVMDetector(cv2.HOGDescriptor_getDefaultPeopleDetector())
    found, missed = 0, []
    for scene in crossing_frames(rig):
        out = renderer.render(scene)
        rects, _ = hog.detectMultiScale(out.left, winStride=(8, 8), padding=(8, 8), scale=1.05)
        dets = [(x, y, x + w, y + h) for x, y, w, h in np.asarray(rects).reshape(-1, 4)]
        peds = [o for o in scene.objects if o.kind is ObjectKind.PEDESTRIAN]
        boxes = [out.boxes_px[o.obj_id] for o in peds]
        for i, a in enumerate(boxes):  # the set is meant to be unoccluded and 100-250 px tall
            assert 100 <= a[3] - a[1] <= 250, (peds[i].obj_id, a)
            assert all(a[2] <= b[0] or b[2] <= a[0] for b in boxes[i + 1:]), (peds[i].obj_id, a)
        for o, box in zip(peds, boxes):
            best = max((iou(detector_window(box), d) for d in dets), default=0.0)
            if best >= 0.5:
                found += 1
            else:
                missed.append((o.obj_id, round(o.pose.yaw_rad, 2), o.speed_mps, box, round(best, 2)))
    total = found + len(missed)
    assert total >= 20
    assert found / total >= 0.9, f"found {found}/{total}; missed (id, yaw, speed, box, best IoU): {missed}"


def _outline_points(batch, i: int) -> np.ndarray:
    """The polygon the rasteriser fills for patch i (world frame, (M, 3))."""
    st = OUTLINES[batch.outline[i]]
    return batch.origin[i] + st[:, :1] * batch.e1[i] + st[:, 1:] * batch.e2[i]


@pytest.mark.parametrize("speed", [0.0, 1.3])
def test_feet_rest_on_the_road_where_the_rig_projects_them(road, speed):
    rig = StereoRig()
    renderer = StereoRenderer(rig, road, seed=0, scenery=False)
    ego = Pose2D(100.0, -6.0, 0.0)
    peds = []
    for j, yaw in enumerate((0.0, math.pi / 2, math.pi, -math.pi / 2, 0.7, -2.5)):
        u, px = 60.0 + 104.0 * j, (110.0, 240.0, 170.0)[j % 3]
        x, y = _place(ego, rig, u, 1.75, px)
        peds.append(ObjectState(j + 1, ObjectKind.PEDESTRIAN, Pose2D(x, y, yaw), 0.5, 0.5, 1.5 + 0.09 * j, style=j + 3,
                                speed_mps=speed, gait_phase=1.1 * j))
    scene = Scene(ego, tuple(peds))
    out = renderer.render(scene)
    patches = renderer.object_patches(scene)
    for o in peds:
        pts = np.concatenate([_outline_points(patches, i) for i in np.flatnonzero(patches.obj_id == o.obj_id)])
        # the lowest point of the figure is on the road (+-2 cm), under the pedestrian
        assert abs(pts[:, 2].min()) <= 0.02
        contact = pts[pts[:, 2] <= pts[:, 2].min() + 0.005]
        assert np.hypot(contact[:, 0] - o.pose.x_m, contact[:, 1] - o.pose.y_m).max() < 0.5
        # the foot point: standing, the sole point nearest the camera; walking, the shoe point lowest in the
        # image (a swing foot nearer the camera is drawn lower than the stance foot although it is lifted)
        feet = contact if o.speed_mps == 0.0 else pts[pts[:, 2] < 0.12]
        xy_v = ego.to_vehicle_xy(feet[:, :2])
        uv, _ = rig.project_vehicle_points(np.column_stack([xy_v, feet[:, 2]]), Side.LEFT)
        foot_row = int(np.round(uv[:, 1].max()))  # the pixel row it falls in (pixel centres at integer v)
        lowest_row = out.boxes_px[o.obj_id][3] - 1  # v1 is exclusive
        assert abs(lowest_row - foot_row) <= 1, (o.obj_id, lowest_row, uv[:, 1].max())


def test_the_figure_builders_vector_formulas_equal_numpys():
    """The tuple arithmetic the figures are built with is numpy's float64 arithmetic, bit for bit; a dot product
    sums left to right where numpy's BLAS may fuse multiply-adds or sum in another order (at most the last bits
    differ)."""
    from percept.sims.render.vec3 import add, cross, dot, madd, mul, norm, sub, vec

    rng = np.random.default_rng(5)
    for (a, b), k in zip(rng.normal(size=(500, 2, 3)) * rng.choice([1e-3, 1.0, 30.0], size=(500, 1, 1)),
                         rng.normal(size=500)):
        ta, tb = vec(a), vec(b)
        # one IEEE product or sum per component, as numpy does them: the same bits on any CPU
        assert np.array_equal(cross(ta, tb), np.cross(a, b))
        assert np.array_equal(add(ta, tb), a + b) and np.array_equal(sub(ta, tb), a - b)
        assert np.array_equal(mul(k, ta), k * a) and np.array_equal(madd(ta, k, tb), a + k * b)
        # a 3-term dot product in any order is within 1.5 eps sum |a_i b_i| of the exact one (Higham 2002, ch. 3),
        # a norm within 1 eps: twice that for two of them, and a margin
        assert dot(ta, tb) == pytest.approx(float(a @ b), rel=0, abs=6 * EPS * float(np.abs(a) @ np.abs(b)))
        assert norm(ta) == pytest.approx(float(np.linalg.norm(a)), rel=4 * EPS)


def test_box_faces_are_the_boxs_six_sides_facing_out():
    """``box_faces`` (PatchBuilder.box's and the shoes'): front, back, left, right, top, bottom, each centred half
    the box's size from its centre along its axis, spanning the other two, e1 x e2 outwards."""
    from percept.sims.render.patches import box_faces

    rng = np.random.default_rng(3)
    for _ in range(50):
        c, size = rng.normal(size=3) * 10, rng.uniform(0.01, 3.0, size=3)
        axes, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        axes = axes.T
        faces = box_faces(tuple(c), tuple(map(tuple, axes)), tuple(size))
        assert len(faces) == 6
        for (o, e1, e2), (k, sign) in zip(faces, [(0, 1), (0, -1), (1, 1), (1, -1), (2, 1), (2, -1)]):
            o, e1, e2 = (np.asarray(v) for v in (o, e1, e2))
            out = sign * axes[k]
            npt.assert_allclose(o + (e1 + e2) / 2 - c, out * size[k] / 2, atol=1e-9)
            n = np.cross(e1, e2)
            assert n @ out > 0
            others = [j for j in range(3) if j != k]
            npt.assert_allclose(sorted([np.linalg.norm(e1), np.linalg.norm(e2)]), sorted(size[others]), rtol=1e-9)
