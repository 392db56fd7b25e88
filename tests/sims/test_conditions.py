"""Photometric conditions on a rendered highway frame: each changes the image the way it claims to."""

import cv2
import numpy as np
import pytest

from percept.sims import Condition, SimWorld, WorldConfig
from percept.sims.conditions import DROPOUT_RATE, ConditionEffects, is_dropped
from percept.sims.world import scene_from_road


@pytest.fixture(scope="module")
def clear():
    w = SimWorld(WorldConfig("highway", 0, autopilot=True))
    frame, _ = w.observe()
    return w.cfg.rig, frame


def grey(img: np.ndarray) -> np.ndarray:
    return cv2.cvtColor(img, cv2.COLOR_BGR2GRAY).astype(np.float64)


def apply(rig, img, condition, frame=0, camera=0, seed=0):
    return ConditionEffects(rig, condition).apply(img, seed, frame, camera)


def regions(rig, img):
    """Grey levels of the sky (above the horizon) and of the road just ahead (bottom rows, centre)."""
    g = grey(img)
    H, W = g.shape
    hz = int(rig.horizon_row)
    return g, g[: hz - 5], g[H - 80:, W // 2 - 100: W // 2 + 100]


@pytest.mark.parametrize("condition", [Condition.CLEAR, Condition.DROPOUT])
def test_clear_and_dropout_leave_the_image_unchanged(clear, condition):
    rig, frame = clear
    out = apply(rig, frame.left, condition)
    assert out.dtype == np.uint8 and np.array_equal(out, frame.left)


@pytest.mark.parametrize("condition", list(Condition))
def test_effects_are_deterministic_and_keep_the_format(clear, condition):
    rig, frame = clear
    a = apply(rig, frame.left, condition, frame=3, camera=1)
    b = apply(rig, frame.left, condition, frame=3, camera=1)
    assert np.array_equal(a, b) and a.shape == frame.left.shape and a.dtype == np.uint8


def test_night_is_dark_but_the_headlights_light_the_road_ahead(clear):
    rig, frame = clear
    g0, sky0, road0 = regions(rig, frame.left)
    g, sky, road = regions(rig, apply(rig, frame.left, Condition.NIGHT))
    assert g.mean() < 0.5 * g0.mean()
    assert sky.mean() < 0.15 * sky0.mean()
    assert road.mean() > 0.8 * road0.mean()
    assert road.mean() > 4 * sky.mean()


def test_rain_lowers_contrast_and_sharpness(clear):
    rig, frame = clear
    g0 = grey(frame.left)
    g = grey(apply(rig, frame.left, Condition.RAIN))
    assert g.std() < 0.75 * g0.std()
    assert cv2.Laplacian(g, cv2.CV_64F).std() < 0.7 * cv2.Laplacian(g0, cv2.CV_64F).std()
    assert abs(g.mean() - g0.mean()) < 30


def test_glare_is_bright_near_the_sun_and_washes_out_contrast(clear):
    rig, frame = clear
    effects = ConditionEffects(rig, Condition.GLARE)
    g0 = grey(frame.left)
    g = grey(effects.apply(frame.left, 0, 0, 0))
    su, sv = (int(round(c)) for c in effects.sun_uv)
    assert g[sv - 10: sv + 10, su - 10: su + 10].mean() > 250
    assert g.mean() > g0.mean() + 30
    assert g.std() / g.mean() < 0.8 * g0.std() / g0.mean()
    # brightness falls off away from the sun
    far = g[-40:, -120:].mean() - g0[-40:, -120:].mean()
    near = g[sv + 20: sv + 60, su - 20: su + 20].mean() - g0[sv + 20: sv + 60, su - 20: su + 20].mean()
    assert near > far + 10


def test_noise_has_sigma_10_and_differs_per_frame_and_camera(clear):
    rig, frame = clear
    img = frame.left
    d = apply(rig, img, Condition.NOISE).astype(np.float64) - img
    # white noise sigma 10 plus row banding sigma 3: sqrt(100 + 9) = 10.4 (a little less where it clips)
    assert 9.5 < d.std() < 11.0
    assert abs(d.mean()) < 1.0
    assert not np.array_equal(apply(rig, img, Condition.NOISE, frame=1), apply(rig, img, Condition.NOISE, frame=2))
    assert not np.array_equal(apply(rig, img, Condition.NOISE, camera=0), apply(rig, img, Condition.NOISE, camera=1))
    assert not np.array_equal(apply(rig, img, Condition.NOISE, seed=1), apply(rig, img, Condition.NOISE, seed=2))


def test_dropout_drops_about_10_percent_of_frames_deterministically():
    runs = {s: [is_dropped(Condition.DROPOUT, s, k) for k in range(300)] for s in range(5)}
    for seed, dropped in runs.items():
        assert abs(np.mean(dropped) - DROPOUT_RATE) < 0.04, (seed, np.mean(dropped))
        assert dropped == [is_dropped(Condition.DROPOUT, seed, k) for k in range(300)]
    assert runs[0] != runs[1]
    # 5 x 300 frames together: 10 % within two binomial sigmas
    assert abs(np.mean(list(runs.values())) - DROPOUT_RATE) < 2 * np.sqrt(0.1 * 0.9 / 1500)
    for c in Condition:
        if c is not Condition.DROPOUT:
            assert not any(is_dropped(c, 0, k) for k in range(300))


def test_world_applies_the_condition_to_both_cameras(clear):
    rig, frame = clear
    w = SimWorld(WorldConfig("highway", 0, condition="night", autopilot=True))
    night, _ = w.observe()
    # the night effect reads each camera's inverse depth and lamp map from the renderer
    img = w.renderer.render(scene_from_road(w.env.road, w.ego, w.ids))
    effects = ConditionEffects(rig, Condition.NIGHT)
    assert np.array_equal(night.left, effects.apply(frame.left, 0, 0, 0, img.inv_depth[0], img.emission[0]))
    assert np.array_equal(night.right, effects.apply(frame.right, 0, 0, 1, img.inv_depth[1], img.emission[1]))
    # only the night reads the lamp map, so the world renders it only then
    assert [c for c in Condition if ConditionEffects(rig, c).reads_emission] == [Condition.NIGHT]


def test_the_headlight_beam_lies_on_the_world_so_both_cameras_see_it_at_the_surface_s_disparity(clear):
    rig, _ = clear
    effects = ConditionEffects(rig, Condition.NIGHT)
    cam = rig.camera
    for z in (8.0, 30.0):
        wall = np.full((cam.height, cam.width), 1.0 / z, np.float32)
        left, right = effects.night_gain(wall, 0), effects.night_gain(wall, 1)
        # a point of the wall at left column u is at u - f b / Z in the right image: the same light there
        d = cam.fx * rig.baseline_m / z
        u = np.arange(100, 540)
        np.testing.assert_allclose(np.interp(u - d, np.arange(cam.width), right[240]), left[240, u], atol=2e-3)
    # the sky gets the ambient light only
    assert np.allclose(effects.night_gain(np.zeros((cam.height, cam.width), np.float32), 0), 0.08)


def test_a_lamp_keeps_its_light_in_proportion_to_the_pixel_it_covers(clear):
    rig, _ = clear
    effects = ConditionEffects(rig, Condition.NIGHT)
    img = np.full((rig.camera.height, rig.camera.width, 3), 200, np.uint8)
    sky = np.zeros(img.shape[:2], np.float32)
    lamp = np.zeros(img.shape[:2], np.float32)
    lamp[100, 100:103] = (1.0, 0.5, 0.25)
    out = effects.night(img.astype(np.float32), effects.night_gain(sky, 0), lamp)
    # lamp fraction e: 200 e + 200 * 0.08 (1 - e), plus the glow around it
    base = 200 * 0.08
    lit = out[100, 100:103, 0] - base
    np.testing.assert_allclose(lit / lit[0], [1.0, 0.5, 0.25], atol=0.06)


def test_world_dropout_frame_has_no_images_but_keeps_imu_and_wheel_speed():
    k = next(k for k in range(1, 300) if is_dropped(Condition.DROPOUT, 0, k))
    w = SimWorld(WorldConfig("highway", 0, condition=Condition.DROPOUT, autopilot=True, scenery=False))
    for _ in range(k - 1):
        w.step()
    before, _ = w.observe()
    w.step()
    dropped, gt = w.observe()
    assert before.index == k - 1 and not before.dropped and before.left is not None
    assert dropped.index == k and dropped.dropped and dropped.left is None and dropped.right is None
    assert dropped.imu.is_finite() and dropped.wheel_speed_mps == pytest.approx(gt.speed_mps, rel=0.05)
