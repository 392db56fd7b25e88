"""Analytic checks of the longitudinal building blocks on synthetic stereo pairs with known disparities."""

import cv2
import numpy as np
import pytest

from percept.longitudinal.obstacles import ObstacleConfig, ObstacleFinder
from percept.longitudinal.refine import refine_disparity, surface_mask
from percept.sensors import EgoPath, StereoRig


def textured(h: int, w: int, seed: int = 0) -> np.ndarray:
    """Smooth random texture (blurred noise), float32 grey levels ~0..255."""
    rng = np.random.default_rng(seed)
    return cv2.GaussianBlur(rng.uniform(0, 255, (h, w)).astype(np.float32), (0, 0), 1.5) * 3 - 255


def shifted(img: np.ndarray, d: float) -> np.ndarray:
    """The right image of a fronto-parallel plane at disparity d: R(u) = L(u + d)."""
    h, w = img.shape
    mx, my = np.meshgrid(np.arange(w, dtype=np.float32) + d, np.arange(h, dtype=np.float32))
    return cv2.remap(img, mx, my, cv2.INTER_CUBIC, borderMode=cv2.BORDER_REFLECT)


@pytest.mark.parametrize("d_true", [4.37, 11.5, 30.08])
def test_direct_alignment_recovers_a_subpixel_disparity(d_true):
    left = textured(120, 200)
    right = shifted(left, d_true)
    r = refine_disparity(left, right, (60, 30, 140, 90), None, round(d_true) + 0.4)
    assert r is not None and r.converged
    assert r.disparity_px == pytest.approx(d_true, abs=0.02)
    assert r.sigma_px < 0.05 and r.pixels == 80 * 60


def test_surface_mask_keeps_the_pixels_at_the_disparity_and_drops_the_background():
    left = textured(100, 200, seed=1)
    near, far = shifted(left, 12.3), shifted(left, 5.0)
    right = far.copy()
    right[:, :] = far
    # the left half of the box is a surface at 12.3 px, the rest background at 5 px
    right[:, :110] = near[:, :110]
    m = surface_mask(left, right, (40, 20, 160, 80), 12.3)
    assert m[:, 10:50].mean() > 0.9 and m[:, 100:].mean() < 0.05
    r = refine_disparity(left, right, (40, 20, 160, 80), m, 12.0)
    assert r.disparity_px == pytest.approx(12.3, abs=0.05)


def test_refinement_gives_up_on_flat_or_out_of_image_patches():
    flat = np.full((60, 100), 128, np.float32)
    assert refine_disparity(flat, flat, (20, 10, 80, 50), None, 5.0) is None
    left = textured(60, 100)
    assert refine_disparity(left, left, (2, 10, 40, 50), None, 10.0) is None  # would sample left of the image


def test_the_finder_reports_a_wall_standing_in_the_path_at_its_range():
    rig = StereoRig()
    cam, fb = rig.camera, rig.camera.fx * rig.baseline_m
    z_wall = 20.0
    left = textured(cam.height, cam.width, seed=3)
    # road below the wall's foot: its disparity grows with the row (d = f b (v - cy) / (f h) on flat ground)
    v = np.arange(cam.height, dtype=np.float32)
    d_rows = np.where(v > cam.cy, fb * (v - cam.cy) / (cam.fy * rig.mount_height_m), 0.0)
    foot = cam.cy + cam.fy * rig.mount_height_m / z_wall
    d_rows = np.where(v < foot, fb / z_wall, d_rows)
    mx = np.arange(cam.width, dtype=np.float32)[None, :] + d_rows[:, None].astype(np.float32)
    my = np.repeat(v[:, None], cam.width, axis=1)
    right = cv2.remap(left, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REFLECT)
    to8 = lambda a: np.clip(a, 0, 255).astype(np.uint8)  # noqa: E731
    ob, dbg = ObstacleFinder(rig).find(to8(left), to8(right), EgoPath.straight(20.0))
    assert ob is not None and ob.range_m == pytest.approx(z_wall, rel=0.05)
    # its lowest standing pixels are min_height_m above the road: f h_min / Z rows above the foot
    assert ob.box_px[3] == pytest.approx(foot - cam.fy * ObstacleConfig().min_height_m / z_wall, abs=3)
    with pytest.raises(ValueError, match="num_disparities must be a multiple of 16"):
        ObstacleConfig(num_disparities=(40, 32))


def test_one_preparation_serves_several_alignments_as_separate_calls_would():
    from percept.longitudinal.refine import PatchAligner

    left = textured(100, 200, seed=3)
    right = shifted(left, 9.6)
    box = (50, 20, 150, 80)
    inner = np.zeros((60, 100), bool)
    inner[:, 10:90] = True
    aligner = PatchAligner(left, right, box)
    first = aligner.refine(None, 9.0)
    second = aligner.refine(inner, first.disparity_px)
    assert first == refine_disparity(left, right, box, None, 9.0)
    assert second == refine_disparity(left, right, box, inner, first.disparity_px)
    assert second.disparity_px == pytest.approx(9.6, abs=0.02) and second.pixels == 60 * 80
