"""The stereo renderer draws things where the rig's projection says they are (analytic checks)."""

import cv2
import numpy as np
import pytest

from percept.sensors import Pose2D, Side
from percept.sims.render import ObjectKind, ObjectState, Scene, StereoRenderer

EGO = Pose2D(100.0, -4.0, 0.0)
"""Ego in lane 1 of highway-env's straight 4-lane road (world y = -4), looking along +x."""


@pytest.fixture(scope="module")
def bare(rig, road):
    """Renderer without roadside scenery."""
    return StereoRenderer(rig, road, seed=3, scenery=False)


def to_vehicle(points_w: np.ndarray) -> np.ndarray:
    """World points (N, 3) -> ego vehicle frame (N, 3)."""
    return EGO.vehicle_from_world().apply(points_w)


def car(oid: int, x_m: float, y_m: float = EGO.y_m, style: int = 3) -> ObjectState:
    return ObjectState(oid, ObjectKind.VEHICLE, Pose2D(x_m, y_m, 0.0), 4.8, 1.9, 1.5, style=style)


def test_ground_depth_is_analytic_and_sky_is_inf(rig, bare):
    out = bare.render(Scene(EGO, ()))
    cam = rig.camera
    v = np.arange(cam.height)
    below = v > rig.horizon_row
    # pitch 0: a ground pixel at row v sees depth Z = f h / (v - cy) at every column
    z = cam.fy * rig.mount_height_m / (v[below] - cam.cy)
    np.testing.assert_allclose(out.depth_m[below], np.repeat(z[:, None], cam.width, 1), rtol=1e-5)
    assert np.isinf(out.depth_m[~below]).all()
    assert (out.ids[~below] == -1).all() and (out.ids[below] == 0).all()


def test_lane_dash_corners_project_where_drawn(rig, road, bare):
    out = bare.render(Scene(EGO, ()))
    q = road.marking_quads
    c = q.mean(axis=1)
    # dashes 12..30 m ahead on the two lines of the ego lane
    near = (c[:, 0] > EGO.x_m + 12) & (c[:, 0] < EGO.x_m + 30) & (np.abs(c[:, 1] - EGO.y_m) < 2.5)
    assert near.sum() >= 2
    gray = cv2.cvtColor(out.left, cv2.COLOR_BGR2GRAY)
    # paint (~236) against asphalt (~105 +- 40): pixels at least half covered by paint
    n, labels = cv2.connectedComponents((gray > 170).astype(np.uint8))
    for quad in q[near]:
        corners = to_vehicle(np.column_stack([quad, np.zeros(4)]))
        uv, _ = rig.project_vehicle_points(corners, Side.LEFT)
        centre = np.round(uv.mean(axis=0)).astype(int)
        lab = labels[centre[1], centre[0]]
        assert lab > 0, "no paint at the dash's projected centre"
        rows, cols = np.nonzero(labels == lab)
        # drawn pixels span the projected corners (pixel centres inside), within a pixel
        assert abs(cols.min() - uv[:, 0].min()) <= 1.0 and abs(cols.max() - uv[:, 0].max()) <= 1.0
        assert abs(rows.min() - uv[:, 1].min()) <= 1.0 and abs(rows.max() - uv[:, 1].max()) <= 1.0


@pytest.mark.parametrize("ahead_m", [9.0, 20.0, 45.0])
def test_vehicle_rear_face_and_silhouette_box(rig, bare, ahead_m, projected_box):
    obj = car(7, EGO.x_m + ahead_m)
    out = bare.render(Scene(EGO, (obj,)))
    # the body's rear face: x = -L/2 in the object frame, |y| <= W/2, z in [0.32, 0.58 H + 0.1]
    x_rear = obj.pose.x_m - obj.length_m / 2
    z_rear = x_rear - EGO.x_m - rig.mount_x_m
    face = (out.ids == 7) & (np.abs(out.depth_m - z_rear) < 0.015)
    rows, cols = np.nonzero(face)
    hw, z0, z1 = obj.width_m / 2, 0.32, 0.58 * obj.height_m + 0.1
    corners = np.array([[x_rear, obj.pose.y_m + s, z] for s in (-hw, hw) for z in (z0, z1)])
    uv, zc = rig.project_vehicle_points(to_vehicle(corners), Side.LEFT)
    np.testing.assert_allclose(zc, z_rear)
    # pixel centres inside the projected rectangle: first and last are within one pixel of its edges
    assert abs(cols.min() - uv[:, 0].min()) <= 1.0 and abs(cols.max() - uv[:, 0].max()) <= 1.0
    assert abs(rows.min() - uv[:, 1].min()) <= 1.0 and abs(rows.max() - uv[:, 1].max()) <= 1.0
    # the depth there is the face's depth (lights and plate sit 1 cm proud of it)
    body = np.abs(out.depth_m - z_rear) < 0.005
    np.testing.assert_allclose(out.depth_m[face & body], z_rear, rtol=1e-5)
    assert (face & body).sum() > 0.7 * face.sum()
    # silhouette box against the projected corners of every patch that faces the left camera
    expected, _, _ = projected_box(obj, rig, EGO)
    np.testing.assert_allclose(out.boxes_px[7], expected, atol=1.0)
    assert out.visible[7] == pytest.approx(1.0)


def test_visible_fraction_under_occlusion(rig, bare):
    # same size, twice as far, straight behind: hidden entirely (its roof stays below the near car's)
    out = bare.render(Scene(EGO, (car(1, EGO.x_m + 12.0), car(2, EGO.x_m + 24.0))))
    assert out.visible[1] == pytest.approx(1.0)
    assert out.visible[2] == 0.0 and not (out.ids == 2).any()
    # shifted 1.2 m sideways: partly visible, and what is visible is what the id map shows
    out = bare.render(Scene(EGO, (car(1, EGO.x_m + 12.0), car(2, EGO.x_m + 24.0, EGO.y_m + 1.2))))
    assert 0.1 < out.visible[2] < 0.9
    u0, v0, u1, v1 = out.boxes_px[2]
    ids = out.ids == 2
    assert ids.any() and not ids[:, :u0].any() and not ids[:, u1:].any() and not ids[:v0].any() and not ids[v1:].any()


def test_same_inputs_render_identical_frames(rig, road):
    scene = Scene(EGO, (car(1, EGO.x_m + 15.0), car(2, EGO.x_m + 40.0, EGO.y_m + 4.0, style=5)))
    a = StereoRenderer(rig, road, seed=11).render(scene)
    r = StereoRenderer(rig, road, seed=11)
    r.render(Scene(Pose2D(150.0, -8.0, 0.1), ()))  # another frame in between must not matter
    b = r.render(scene)
    for name in ("left", "right", "depth_m", "ids"):
        assert getattr(a, name).tobytes() == getattr(b, name).tobytes(), name
    assert a.boxes_px == b.boxes_px and a.visible == b.visible


def test_the_reused_winner_map_is_left_clear_and_an_interrupted_frame_does_not_leak(rig, road):
    # the large patches' scratch map is lent to each frame and cleared over the boxes it drew on
    scene = Scene(EGO, (car(1, EGO.x_m + 8.0), car(2, EGO.x_m + 20.0, EGO.y_m + 4.0, style=5)))
    r = StereoRenderer(rig, road, seed=11)
    first = r.render(scene)
    for side in (Side.LEFT, Side.RIGHT):
        assert (r.winners[side].map == -1).all(), side
    # a rasterisation stopped half-way (Ctrl-C) leaves the map lent and dirty: the next frame fills it afresh
    dirty = r.winners[Side.LEFT].take()
    dirty[200:400, 100:500] = 3
    again = r.render(scene)
    for name in ("left", "right", "depth_m", "ids"):
        assert getattr(first, name).tobytes() == getattr(again, name).tobytes(), name
    assert (r.winners[Side.LEFT].map == -1).all()


def test_without_the_lamp_map_the_frames_are_the_same(rig, road):
    scene = Scene(EGO, (car(1, EGO.x_m + 8.0), car(2, EGO.x_m + 30.0, EGO.y_m + 4.0, style=5)))
    r = StereoRenderer(rig, road, seed=11)
    lit, plain = r.render(scene), r.render(scene, emission=False)
    assert lit.emission[0].max() == 1.0 and plain.emission == (None, None)
    for name in ("left", "right", "depth_m", "ids"):
        assert getattr(lit, name).tobytes() == getattr(plain, name).tobytes(), name
    assert lit.boxes_px == plain.boxes_px and lit.visible == plain.visible


def test_prepare_takes_cameras_of_one_orientation_only(rig, bare):
    from percept.sensors.poses import Transform
    from percept.sims.render.patches import SUN_DIR
    from percept.sims.render.raster import prepare

    scene = Scene(EGO, (car(1, EGO.x_m + 15.0),))
    patches = bare.scene_patches(scene)
    left, right = (bare.cam_from_world(scene, s) for s in (Side.LEFT, Side.RIGHT))
    # as np.allclose decides: a rotation 1e-9 off is the same orientation, one 1e-3 rad off is not
    nudged = Transform(left.R + 1e-9, right.t)
    assert all(p is not None for p in prepare(patches, rig.camera, [left, nudged], bare.atlas, SUN_DIR))
    c, s = np.cos(1e-3), np.sin(1e-3)
    turned = Transform(np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]]) @ left.R, right.t)
    with pytest.raises(ValueError, match="one orientation"):
        prepare(patches, rig.camera, [left, turned], bare.atlas, SUN_DIR)
