"""Speckles: patches that sensor noise at night and rain streaks match by chance stand up from the road near the car,
and joined to a car pulling out close by they made one group too wide for any vehicle. Both rigs drop them far away, the
forward rig near by too; the rear rig flags them near by, and a group too wide is grouped again without them."""

import numpy as np
import pytest

from percept.neighbours import NeighbourSlot
from percept.neighbours.points import BandStereo, PointsConfig
from percept.sims.world import SimWorld, WorldConfig

from .conftest import truth_path


@pytest.mark.slow
@pytest.mark.parametrize("condition", ["night", "rain"])
def test_a_car_pulling_out_close_by_is_found_at_night_and_in_rain(condition):
    w = SimWorld(WorldConfig("cut-in-close", 0, condition=condition, autopilot=True))
    finder = NeighbourSlot(w.cfg.rig, None, w.dt).front
    for _ in range(160):  # the slow car pulls out 11 s into the run
        w.step()
    found = []
    for _ in range(20):
        w.step()
        frame, gt = w.observe()
        dets, _ = finder.find(frame.left_gray, frame.right_gray, truth_path(gt).lane)
        # the car pulling out, while its centre is 6-25 m ahead (nearer, the image's edge cuts off its face)
        for o in gt.objects:
            x, y = o.position_m[:2]
            if 6.0 <= x <= 25.0 and abs(y) < 6.0:
                found.append(any(abs(d.x_m - x) < 3.0 and abs(d.lat_m - y) < 1.0 for d in dets))
    assert len(found) >= 15
    assert np.mean(found) >= 0.9


def test_noise_matched_by_chance_is_speckles_and_a_textured_face_is_not():
    rig = SimWorld(WorldConfig("highway", 0)).cfg.rig
    cam = rig.camera
    rng = np.random.default_rng(0)
    # a flat grey scene with independent sensor noise in each image (night's gain), and a textured face 40 x 40 px
    # at 20 px disparity in the band
    left, right = (np.clip(90 + rng.normal(0, 8, (cam.height, cam.width)), 0, 255).astype(np.uint8) for _ in "lr")
    v0 = int(rig.horizon_row) + 4
    face = rng.integers(0, 255, (40, 40), dtype=np.uint8)
    left[v0:v0 + 40, 300:340], right[v0:v0 + 40, 280:320] = face, face
    pts = BandStereo(rig, PointsConfig(min_height_m=-10.0, drop_far_speckles=False)).points(left, right)
    on_face = (pts.u >= 300) & (pts.u < 340) & (np.abs(pts.d - 20.0) <= 1.0)
    assert (~on_face).sum() > 200
    assert pts.speckle[~on_face].mean() > 0.75
    assert on_face.sum() > 100
    assert pts.speckle[on_face].mean() < 0.2
    # dropped outright: the noise is gone, the face kept
    kept = BandStereo(rig, PointsConfig(min_height_m=-10.0, drop_near_speckles=True)).points(left, right)
    kept_face = (kept.u >= 300) & (kept.u < 340) & (np.abs(kept.d - 20.0) <= 1.0)
    assert (~kept_face).sum() < 0.25 * (~on_face).sum()
    assert kept_face.sum() > 0.8 * on_face.sum()
