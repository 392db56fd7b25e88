"""The renderer's compiled kernels (numba). The rasteriser's two paths (large patches one by one, small ones as
fragments) draw the same picture: the same scene forced through one path and then the other gives the same image,
ids, lamp map and silhouettes; a patch cut by the near plane is drawn where its rays land. The ground's colour
lookup is OpenCV's to the byte, and the depth read off the z-buffer is numpy's."""

import numpy as np
import pytest

from percept.sensors import PinholeCamera, Transform
from percept.sims.render import fragments
from percept.sims.render.patches import PatchBuilder
from percept.sims.render.raster import RenderTarget, rasterize

CAM = PinholeCamera(150.0, 150.0, 80.0, 60.0, 160, 120)


def scene() -> PatchBuilder:
    """Untextured quads and discs at several depths, overlapping, tilted, one of them a lamp."""
    b = PatchBuilder()
    rng = np.random.default_rng(5)
    for k in range(14):
        z = 3.0 + 0.7 * k
        o = np.array([rng.uniform(-2, 1), rng.uniform(-1.5, 0.5), z])
        e1 = np.array([rng.uniform(0.5, 1.5), 0.0, rng.uniform(-0.5, 0.5)])
        e2 = np.array([rng.uniform(-0.3, 0.3), rng.uniform(0.5, 1.2), 0.0])
        b.add(o, e1, e2, tuple(rng.uniform(20, 250, 3)), outline=int(k % 3 == 0), two_sided=True, shade=k % 4 != 1,
              obj_id=k + 1)
    return b


def draw(monkeypatch, big_px: float) -> RenderTarget:
    monkeypatch.setattr(fragments, "BIG_PX", big_px)
    h, w = CAM.height, CAM.width
    target = RenderTarget(np.full((h, w, 3), 30, np.uint8), np.full((h, w), np.inf, np.float32),
                          np.zeros((h, w), np.int32), emission=np.zeros((h, w), np.float32))
    rasterize(target, scene().build(), CAM, Transform(np.eye(3), np.zeros(3)), [np.zeros((4, 4), np.uint8)],
              np.array([0.3, -1.0, -0.5]) / np.linalg.norm([0.3, -1.0, -0.5]))
    return target


def test_large_and_small_patch_paths_draw_the_same_picture(monkeypatch):
    one_by_one = draw(monkeypatch, -1.0)   # every patch large: boxes, one at a time
    fragments_ = draw(monkeypatch, np.inf)  # every patch small: fragments, all at once
    assert (one_by_one.ids > 0).sum() > 3000, "the scene should cover a good part of the image"
    assert len(np.unique(one_by_one.ids)) >= 10
    # both paths test coverage and depth with the same float32 operations: the same picture to the bit on any CPU
    np.testing.assert_array_equal(one_by_one.ids, fragments_.ids)
    np.testing.assert_array_equal(one_by_one.image, fragments_.image)
    np.testing.assert_array_equal(one_by_one.emission, fragments_.emission)
    assert one_by_one.emission.max() == 1.0
    np.testing.assert_allclose(one_by_one.depth, fragments_.depth, rtol=1e-6)
    assert sorted(one_by_one.silhouettes) == sorted(fragments_.silhouettes)
    for oid in one_by_one.silhouettes:
        assert one_by_one.silhouette(oid) == fragments_.silhouette(oid)
        # a silhouette counts every pixel the patch covers, hidden or not: more than it shows
        box, count, seen = one_by_one.silhouette(oid)
        assert 0 <= seen <= count


@pytest.mark.parametrize("big_px", [-1.0, np.inf])
def test_a_patch_behind_another_is_hidden_in_both_paths(monkeypatch, big_px):
    monkeypatch.setattr(fragments, "BIG_PX", big_px)
    h, w = CAM.height, CAM.width
    target = RenderTarget(np.zeros((h, w, 3), np.uint8), None, np.zeros((h, w), np.int32),
                          np.zeros((h, w), np.float32))
    b = PatchBuilder()
    # added far, near, farther: the near one wins whatever the order
    for z, grey, oid in ((6.0, 200.0, 1), (4.0, 100.0, 2), (8.0, 50.0, 3)):
        b.add(np.array([-1.0, -1.0, z]), np.array([2.0, 0, 0]), np.array([0, 2.0, 0]), (grey,) * 3,
              two_sided=True, shade=False, obj_id=oid)
    rasterize(target, b.build(), CAM, Transform(np.eye(3), np.zeros(3)), [np.zeros((4, 4), np.uint8)],
              np.array([0.0, 0.0, -1.0]))
    # the centre pixel sees the nearest patch (z = 4): its id, its colour and 1/Z = 1/4
    assert target.ids[60, 80] == 2
    assert tuple(target.image[60, 80]) == (100, 100, 100)
    assert target.inv_depth[60, 80] == pytest.approx(0.25, rel=1e-6)


def test_a_floor_cut_by_the_near_plane_is_drawn_exactly_where_its_rays_land():
    h, w = CAM.height, CAM.width
    target = RenderTarget(np.zeros((h, w, 3), np.uint8), np.full((h, w), np.inf, np.float32),
                          np.zeros((h, w), np.int32))
    b = PatchBuilder()
    # a floor 1 m below the camera (camera y points down), x in [-1, 1], z from 1 m behind the camera to 5 m ahead
    b.add(np.array([-1.0, 1.0, -1.0]), np.array([2.0, 0, 0]), np.array([0, 0, 6.0]), (200.0,) * 3, two_sided=True,
          shade=False, obj_id=7)
    # a one-sided wall facing away from the camera (its e1 x e2 along +z) is culled
    b.add(np.array([-1.0, -1.0, 4.0]), np.array([2.0, 0, 0]), np.array([0, 0.5, 0]), (90.0,) * 3, obj_id=8)
    rasterize(target, b.build(), CAM, Transform(np.eye(3), np.zeros(3)), [np.zeros((4, 4), np.uint8)],
              np.array([0.0, 0.0, -1.0]))
    u, v = np.meshgrid(np.arange(w, dtype=float), np.arange(h, dtype=float))
    with np.errstate(divide="ignore", invalid="ignore"):
        # the ray through pixel (u, v) meets the floor y = 1 at Z = fy / (v - cy), X = (u - cx) Z / fx
        z = np.where(v > CAM.cy, CAM.fy / (v - CAM.cy), np.inf)
        x = (u - CAM.cx) * z / CAM.fx
    expected = (z >= fragments.NEAR_M) & (z <= 5.0) & (np.abs(x) <= 1.0)
    assert expected.sum() > 2000
    assert (target.ids == 8).sum() == 0
    # pixel centres exactly on the outline may go either way in floating point
    assert ((target.ids == 7) != expected).sum() <= 0.01 * expected.sum()
    np.testing.assert_allclose(target.depth[expected & (target.ids == 7)], z[expected & (target.ids == 7)], rtol=1e-5)


def test_a_silhouette_is_summarised_from_its_distinct_pixels():
    """Box, distinct pixel count and pixels showing the object, from pixel lists that repeat pixels (two patches
    of one object overlap) and are partly hidden (the id map shows another object there)."""
    h, w = 6, 10
    ids = np.zeros((h, w), np.int32)
    ids[2, 3:6] = 7
    ids[3, 4] = 9  # hidden by object 9
    target = RenderTarget(np.zeros((h, w, 3), np.uint8), np.full((h, w), np.inf, np.float32), ids)
    target.silhouettes[7] = [np.array([2 * w + 3, 2 * w + 4, 2 * w + 5], np.int32),
                             np.array([2 * w + 4, 3 * w + 4, 4 * w + 1], np.int32)]
    assert target.silhouette(7) == ((1, 2, 6, 5), 5, 3)
    assert target.silhouette(8) is None
    no_ids = RenderTarget(target.image, target.depth, None, silhouettes={7: target.silhouettes[7]})
    assert no_ids.silhouette(7) == ((1, 2, 6, 5), 5, 0)


def test_the_ground_colour_lookup_is_opencv_s_or_and_colour_map_to_the_byte():
    """``_colour_map`` = ``cv2.bitwise_or`` of the grain and the road mask, then ``cv2.applyColorMap``, on the rows
    below the horizon; the rows above are not touched."""
    import cv2

    from percept.sims.render.ground import _colour_map

    rng = np.random.default_rng(3)
    h, w, r0 = 40, 57, 9
    grain = rng.integers(0, 128, (h - r0, w), dtype=np.uint8)
    mask = np.where(rng.random((h, w)) < 0.4, 128, 0).astype(np.uint8)
    cmap = rng.integers(0, 256, (256, 1, 3), dtype=np.uint8)
    img = np.full((h, w, 3), 7, np.uint8)
    _colour_map(img, grain, mask, cmap, r0)
    expected = cv2.applyColorMap(cv2.bitwise_or(grain, mask[r0:]), cmap)
    np.testing.assert_array_equal(img[r0:], expected)  # integer operations: the same bytes on any CPU
    assert (img[:r0] == 7).all()


def test_the_depth_from_the_z_buffer_is_numpy_s_divide_to_the_bit():
    """``zbuffer_depth``: float32 1 / (1/Z) where a patch changed the z-buffer, the background's depth elsewhere
    (inf for the sky stays inf), equal to numpy's masked divide bit for bit."""
    from percept.sims.render.pixels import zbuffer_depth

    rng = np.random.default_rng(4)
    base = rng.uniform(0.001, 0.5, (30, 41)).astype(np.float32)
    base[:5] = 0.0  # sky: 1/Z = 0
    background = np.where(base > 0, np.float32(1.0) / np.where(base > 0, base, 1), np.inf).astype(np.float32)
    inv = base.copy()
    won = rng.random(base.shape) < 0.3
    inv[won] = rng.uniform(0.05, 2.0, won.sum()).astype(np.float32)
    out = zbuffer_depth(inv, base, background)
    expected = background.copy()
    np.divide(np.float32(1.0), inv, out=expected, where=inv != base)
    assert out.dtype == np.float32
    np.testing.assert_array_equal(out.view(np.int32), expected.view(np.int32))  # IEEE division: one quotient
    assert np.isinf(out[:5][~won[:5]]).all()


@pytest.mark.slow
def test_the_columns_kept_for_a_patch_crossing_the_near_plane_hold_every_pixel_its_exact_test_passes():
    """``_near_columns`` skips only columns where the exact float32 test of a patch crossing the near plane fails:
    checked against the test itself on 20 000 random rows, steep, shallow and flat edges among them."""
    from percept.sims.render.pixels import _near_columns

    rng = np.random.default_rng(6)
    inv_near = np.float32(1.0 / 0.3)
    x = np.arange(-40, 700).astype(np.float32)
    kept_share = []
    for n in range(20_000):
        scale = 10.0 ** rng.uniform(-7, 0, 3) * rng.choice([-1, 1], 3) * (rng.random(3) > 0.05)
        ma0, mb0, mc0 = (np.float32(v) for v in scale)
        ay, by = (np.float32(v) for v in rng.normal(0, 3, 2))
        cy = np.float32(rng.uniform(-0.5, 4.0))
        xa, xb = (int(v) for v in np.sort(rng.integers(-40, 700, 2)))
        xs = x[xa + 40:xb + 40]
        ap, bp, c = ma0 * xs + ay, mb0 * xs + by, mc0 * xs + cy
        quad = (np.maximum(np.abs(ap), np.abs(bp)) <= c) & (c < inv_near) & (c > 0)
        disc = (ap * ap + bp * bp <= c * c) & (c < inv_near) & (c > 0)
        lo, hi = _near_columns(xa, xb, ma0, ay, mb0, by, mc0, cy, inv_near)
        kept = np.zeros(len(xs), bool)
        kept[max(lo - xa, 0):max(hi - xa, 0)] = True
        assert not (quad & ~kept).any() and not (disc & ~kept).any(), (n, xa, xb, lo, hi)
        assert xa <= lo and hi <= xb or hi <= lo
        if len(xs):
            kept_share.append(kept.mean())
    assert np.mean(kept_share) < 0.5, "the bounds should cut most of the columns the test rejects"


def test_the_near_plane_columns_keep_every_column_when_a_bound_cannot_be_told():
    """A slope so shallow that the bound overflows any integer, or a coefficient that is not finite: every column
    is kept, none is lost."""
    from percept.sims.render.pixels import _near_columns

    tiny = np.float32(1e-45)  # the smallest float32 step: the bound lies ~1e45 columns away
    inv_near = np.float32(1.0 / 0.3)
    assert _near_columns(0, 640, tiny, np.float32(0.0), np.float32(0.0), np.float32(0.0), np.float32(0.0),
                         np.float32(1.0), inv_near) == (0, 640)
    assert _near_columns(0, 640, np.float32(0.0), np.float32(np.nan), np.float32(0.0), np.float32(0.0),
                         np.float32(0.0), np.float32(1.0), inv_near) == (0, 640)
