"""Edge coverage (horizontal anti-aliasing): a vertical edge's pixel shows the patch in proportion to the area it
covers, so an edge moves smoothly with the object instead of in whole-pixel steps (analytic checks)."""

import numpy as np
import pytest

from percept.sensors import PinholeCamera, Transform
from percept.sims.render.patches import PatchBuilder
from percept.sims.render.raster import RenderTarget, rasterize

CAM = PinholeCamera(500.0, 500.0, 32.0, 24.0, 64, 48)
BG, FG, OCCLUDER = 40.0, 240.0, 120.0
ROW = CAM.height // 2


def draw(rects: list[tuple[float, float, float, float]], antialias: bool = True) -> np.ndarray:
    """Fronto-parallel rectangles (left edge column [px], width [px], depth [m], grey) on a background at infinity;
    pixel centres are at integer columns. Returns row ROW of the grey image."""
    image = np.full((CAM.height, CAM.width, 3), BG, np.uint8)
    target = RenderTarget(image, None, None, np.zeros((CAM.height, CAM.width), np.float32))
    b = PatchBuilder()
    for k, (left_px, width_px, z_m, grey) in enumerate(rects):
        # u = fx x / Z + cx: the rectangle spans x in [(u0 - cx) Z / fx, (u0 + w - cx) Z / fx]
        x0 = (left_px - CAM.cx) * z_m / CAM.fx
        b.add(np.array([x0, -0.1, z_m]), np.array([width_px * z_m / CAM.fx, 0, 0]), np.array([0, 0.2, 0]),
              (grey,) * 3, two_sided=True, shade=False, obj_id=k + 1)
    rasterize(target, b.build(), CAM, Transform(np.eye(3), np.zeros(3)), [np.zeros((4, 4), np.uint8)],
              np.array([0.0, 0.0, -1.0]), antialias=antialias)
    return image[ROW, :, 0].astype(float)


def coverage(row: np.ndarray) -> np.ndarray:
    return (row - BG) / (FG - BG)


def test_a_row_holds_the_rectangle_s_exact_width_and_its_edges_move_smoothly():
    centroids = []
    for shift in np.arange(0.0, 1.0, 0.1):
        c = coverage(draw([(20.0 + shift, 10.3, 10.0, FG)]))
        # box filter: the row's coverage sums to the width whatever the subpixel position (uint8 rounding aside)
        assert c.sum() == pytest.approx(10.3, abs=0.02)
        centroids.append(float((c * np.arange(CAM.width)).sum() / c.sum()))
    # the centroid follows the rectangle in steps of 0.1 px
    np.testing.assert_allclose(np.diff(centroids), 0.1, atol=0.02)


def test_without_coverage_the_edges_lock_to_whole_pixels():
    widths = {float(coverage(draw([(20.0 + s, 10.3, 10.0, FG)], antialias=False)).sum()) for s in np.arange(0, 1, 0.1)}
    # pixel-centre sampling: the drawn width is 10 or 11 px, never 10.3
    assert widths <= {10.0, 11.0}


def test_an_edge_hidden_behind_a_nearer_patch_is_not_blended():
    # a grey occluder at 5 m over columns 14.6-24.6 hides the white rectangle's left edge (at 20.3, 10 m)
    row = draw([(20.3, 10.0, 10.0, FG), (14.6, 10.0, 5.0, OCCLUDER)])
    # inside the occluder nothing of the white shows; its own edges are blended with what is behind them
    assert (row[16:25] == OCCLUDER).all() and row[14] == BG
    # pixel 15 ([14.5, 15.5]) is 0.9 occluder; pixel 25 ([24.5, 25.5]) is 0.1 occluder over the white
    assert row[15] == pytest.approx(BG + 0.9 * (OCCLUDER - BG), abs=1)
    assert row[25] == pytest.approx(FG + 0.1 * (OCCLUDER - FG), abs=1)
