"""The compiled passes of the obstacle finder and the disparity refinement against numpy's formulas: the same
results, bit for bit."""

import numpy as np
import pytest

from percept.compiled import pairwise_sum
from percept.longitudinal.ground import GroundConfig, _road_points
from percept.longitudinal.lift import lift_band, lift_bands
from percept.longitudinal.refine import _weighted_sums


def _numpy_lift(d16, c0, skip, u, v, rays, fb_scaled, z_min, z_max, origin):
    """The finder's numpy before the kernel: mask, gathers, depth, range cut, lift."""
    c1 = c0 + d16.shape[1]
    ok = d16 > 0
    ok[:, :skip] = False
    z = fb_scaled / d16[ok].astype(np.float32)
    sl = (slice(None), slice(c0, c1))
    uu, vv, rr = u[sl][ok], v[sl][ok], rays[sl][ok]
    keep = (z > z_min) & (z < z_max)
    return uu[keep], vv[keep], z[keep], rr[keep] * z[keep][:, None] + origin


@pytest.mark.parametrize("c0, skip", [(0, 0), (37, 48), (90, 5)])
def test_lifted_matches_equal_numpys_bit_for_bit(c0, skip):
    rng = np.random.default_rng(c0)
    rows, w, cols = 23, 200, 101
    # disparities of every sign, many unmatched (<= 0), some so small or large that the range cut drops them
    d16 = rng.integers(-20, 800, size=(rows, cols)).astype(np.int16)
    u = rng.uniform(0, 640, (rows, w)).astype(np.float32)
    v = rng.uniform(0, 480, (rows, w)).astype(np.float32)
    rays = rng.normal(size=(rows, w, 3)).astype(np.float32)
    origin = np.array([0.8, 0.27, 1.4])
    fb_scaled = 480.0 * 0.3 * 16.0 * 0.37  # not a float32: rounded once, as numpy rounds a Python float
    ref = _numpy_lift(d16, c0, skip, u, v, rays, fb_scaled, 3.3, 100.0, origin)
    got = lift_band(d16, c0, skip, u, v, rays, fb_scaled, 3.3, 100.0, origin)
    assert 0 < len(got[0]) < int((d16 > 0).sum())  # the cut dropped some matches and kept others
    for a, b in zip(ref, got):
        assert a.dtype == b.dtype and a.shape == b.shape
        assert a.tobytes() == b.tobytes()


def test_two_bands_lift_into_their_concatenation():
    rng = np.random.default_rng(5)
    bands, refs = [], []
    for rows, w, cols, c0, skip, area in ((11, 120, 70, 20, 16, 4.0), (9, 80, 80, 0, 0, 16.0)):
        d16 = rng.integers(-20, 800, size=(rows, cols)).astype(np.int16)
        u, v = (rng.uniform(0, 640, (rows, w)).astype(np.float32) for _ in range(2))
        rays = rng.normal(size=(rows, w, 3)).astype(np.float32)
        fb = 480.0 * 0.3 * 16.0 / area ** 0.5
        bands.append((d16, c0, skip, u, v, rays, fb, area))
        ref = _numpy_lift(d16, c0, skip, u, v, rays, fb, 3.3, 100.0, np.array([0.8, 0.27, 1.4]))
        refs.append((*ref, np.full(len(ref[0]), area, np.float32)))
    got = lift_bands(bands, 3.3, 100.0, np.array([0.8, 0.27, 1.4]))
    for k, g in enumerate(got):
        want = np.concatenate([r[k] for r in refs])
        assert g.dtype == want.dtype and g.tobytes() == want.tobytes()


def _numpy_road_points(points, u_px, offset, slope, cfg):
    lo = np.floor(cfg.min_range_m / cfg.cell_m) * cfg.cell_m
    hi = (np.floor(cfg.max_range_m / cfg.cell_m) + 1) * cfg.cell_m
    sel = (points[:, 0] >= lo) & (points[:, 0] < hi)
    points, u_px = points[sel], u_px[sel]
    x, y, z = points[:, 0], points[:, 1], points[:, 2]
    h = z - (offset + slope * x)
    near = (x > cfg.min_range_m) & (x < cfg.max_range_m) & (np.abs(y) < cfg.half_width_m) & (np.abs(h) < cfg.band_m)
    cell_u, cell_x = (u_px // cfg.cell_px).astype(int), np.floor(x / cfg.cell_m).astype(int)
    up = (h > cfg.band_m) & (h < cfg.max_standing_m) & (x > 0)
    key = cell_u * 100003 + cell_x
    near &= ~np.isin(key, key[up])
    return x[near], z[near]


@pytest.mark.parametrize("cell_px", [16, 12, 8, 1])
def test_road_points_equal_numpys(cell_px):
    cfg = GroundConfig(cell_px=cell_px)
    rng = np.random.default_rng(cell_px)
    n = 5000
    # points 0-25 m ahead, mostly on a slightly tilted road, some standing (an obstacle's low parts share cells)
    x = rng.uniform(0, 25, n)
    z = 0.05 + 0.01 * x + rng.normal(0, 0.2, n)
    standing = rng.random(n) < 0.05
    z[standing] += rng.uniform(0.5, 4.0, int(standing.sum()))
    points = np.column_stack([x, rng.uniform(-8, 8, n), z])
    u_px = rng.uniform(0, 639.5, n).astype(np.float32)
    u_px[:50] = np.float32(cell_px) * rng.integers(0, 40, 50)  # on cell boundaries
    offset, slope = 0.03, 0.012
    ref = _numpy_road_points(points, u_px, offset, slope, cfg)
    got = _road_points(points, u_px, offset, slope, cfg.band_m, cfg.min_range_m, cfg.max_range_m, cfg.half_width_m,
                       np.float32(cfg.cell_px), cfg.cell_m, cfg.max_standing_m)
    assert 100 < len(ref[0]) < n
    for a, b in zip(ref, got):
        assert a.dtype == b.dtype and a.tobytes() == b.tobytes()


def test_no_points_give_no_road_points():
    got = _road_points(np.zeros((0, 3)), np.zeros(0, np.float32), 0.0, 0.0, 0.5, 4.0, 16.0, 6.0, np.float32(16), 3.0,
                       3.5)
    assert got[0].shape == (0,) and got[1].shape == (0,)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_pairwise_sum_equals_numpys_sum_at_every_length(dtype):
    """numpy sums a contiguous array pairwise; a sequential sum of the same float32 values differs in the last bits
    at a few hundred elements already, so this tells the two apart."""
    rng = np.random.default_rng(7)
    sequential_differs = 0
    for n in [*range(0, 300), 1000, 1031, 4096, 8191, 8192, 8193, 20011]:
        a = (rng.normal(size=n) * 37.0).astype(dtype)
        assert pairwise_sum(a, 0, n) == np.sum(a), n
        sequential_differs += dtype == np.float32 and n > 200 and float(np.cumsum(a)[-1]) != float(np.sum(a))
    assert dtype == np.float64 or sequential_differs > 0
    # a sum of negative zeros is +0 in numpy (its reduction starts from the identity)
    for n in (3, 8, 200):
        zeros = np.full(n, -0.0, dtype)
        assert not np.signbit(pairwise_sum(zeros, 0, n)) and not np.signbit(np.sum(zeros))


def test_gauss_newton_sums_equal_numpys():
    rng = np.random.default_rng(3)
    L = rng.uniform(0, 255, (17, 45)).astype(np.float32)
    both = np.stack([L + rng.normal(0, 9, L.shape), rng.normal(0, 20, L.shape)], axis=-1).astype(np.float32)
    keep = rng.random(L.shape) < 0.8
    r = L - both[..., 0]
    a = np.abs(r)
    wts = np.where(a <= 6.0, 1.0, 6.0 / np.maximum(a, 1e-6)) * keep
    g = both[..., 1]
    got = _weighted_sums(L[:, 2:40], both[:, 2:40], keep[:, 2:40], np.float32(6.0))
    ref = tuple(np.sum(x[:, 2:40]) for x in (wts * g * g, wts * g * r, wts * r * r))
    assert all(x.dtype == np.float32 for x in ref)
    assert got == ref


def test_mismatched_inputs_raise_instead_of_reading_past_the_arrays():
    u = np.zeros((4, 10), np.float32)
    with pytest.raises(ValueError, match="do not fit the band"):
        lift_band(np.ones((4, 8), np.int16), 5, 0, u, u, np.zeros((4, 10, 3), np.float32), 1.0, 0.0, 10.0, np.zeros(3))
    from percept.longitudinal import GroundPlane, PatchAligner
    with pytest.raises(ValueError, match=r"points \(N, 3\) and columns \(N,\)"):
        GroundPlane().update(np.zeros((5, 3)), np.zeros(4, np.float32))
    img = np.random.default_rng(0).uniform(0, 255, (20, 60)).astype(np.float32)
    with pytest.raises(ValueError, match="must match the patch"):
        PatchAligner(img, img, (20, 2, 40, 12)).refine(np.ones((5, 5), bool), 4.0)


WARM_CHECK = """
from percept.compiled import dispatchers
from percept.drive import SlotContext, TruthFeed
from percept.drive.tasks import TASKS
from percept.lanes import evidence
from percept.sensors import EgoPath, Lead
from percept.longitudinal import contact, flow, ground, groups, lift, refine
from percept.odometry import features
from percept.sims import SimWorld, WorldConfig
from percept.sims.coords import hw_pose
modules = (evidence, contact, flow, ground, groups, lift, refine, features)
kernels = dispatchers(*modules)
world = SimWorld(WorldConfig("lead-brake", seed=1, autopilot=True))
ctx = SlotContext(world.cfg.rig, world.dt, None, TruthFeed(), start_pose=hw_pose(world.ego))
slots = {t.name: t.vision(ctx) for t in TASKS if t.name in ("lanes", "longitudinal", "odometry")}
before = [len(k.signatures) for k in kernels]
refined = 0
for _ in range(45):
    frame, _ = world.observe()
    path = slots["lanes"].step(frame, {})[0]
    lead = slots["longitudinal"].step(frame, {EgoPath: path})
    refined += lead[1].refined is not None
    slots["odometry"].step(frame, {Lead: lead[0]})
    world.step()
print(len(kernels), min(before), refined, [len(k.signatures) for k in kernels] == before)
"""


@pytest.mark.slow
def test_the_slots_load_their_compiled_passes_when_built_not_in_a_frame():
    """The lanes', longitudinal and odometry slots' compiled passes."""
    import subprocess
    import sys

    # in a fresh process (this one has called the kernels above already)
    out = subprocess.run([sys.executable, "-c", WARM_CHECK], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    count, least, refined, unchanged = out.stdout.split()
    # every kernel loaded by the slots' construction; the lead was refined (and the odometry started keyframes), so
    # every pass ran in the frames
    assert int(count) == 13 and int(least) >= 1 and int(refined) > 10 and unchanged == "True"


def _numpy_surface_mask(left, right, box, d0, radius=3, block=5, tol_px=1.0, min_contrast=3.0, max_cost_ratio=0.5):
    import cv2
    u0, v0, u1, v1 = box
    lo = int(np.floor(d0)) - radius
    L = left[v0:v1, u0:u1]
    c = np.stack([cv2.blur(np.abs(L - right[v0:v1, u0 - d:u1 - d]), (block, block))
                  for d in range(lo, lo + 2 * radius + 2)])
    k = np.clip(np.argmin(c, axis=0), 1, len(c) - 2)
    c0, c1, c2 = (np.take_along_axis(c, (k + j)[None], 0)[0] for j in (-1, 0, 1))
    den = c0 - 2 * c1 + c2
    best = lo + k + np.where(den > 1e-6, (c0 - c2) / (2 * np.maximum(den, 1e-6)), 0.0)
    mean = np.mean(c, axis=0)
    return (np.abs(best - d0) < tol_px) & (den > 1e-6) & (mean - c1 > min_contrast) & (c1 < max_cost_ratio * mean)


def test_surface_mask_equals_numpys_and_refuses_a_box_without_room_for_its_candidates():
    from percept.longitudinal import surface_mask

    rng = np.random.default_rng(4)
    kept = 0
    for _ in range(40):
        h, w = int(rng.integers(6, 30)), int(rng.integers(60, 120))
        left = rng.uniform(0, 255, (h, w)).astype(np.float32)
        shift = int(rng.integers(6, 12))
        right = (np.roll(left, -shift, axis=1) + rng.normal(0, 4, (h, w))).astype(np.float32)
        box = (int(rng.integers(22, 30)), 0, w - int(rng.integers(1, 5)), h)
        d0 = shift + float(rng.uniform(-1.0, 1.0))
        got, ref = surface_mask(left, right, box, d0), _numpy_surface_mask(left, right, box, d0)
        assert got.dtype == ref.dtype and np.array_equal(got, ref)  # the same float32 operations: the same mask
        kept += int(got.sum())
    assert kept > 1000
    # at d0 = 8.5 the candidates run to d = 12, left of a box starting at column 10: a check for room for d <= 9
    # alone would let it through, and forming the costs would fail on an empty slice; there is no mask
    img = rng.uniform(0, 255, (10, 80)).astype(np.float32)
    assert surface_mask(img, img, (10, 0, 60, 10), 8.5) is None
    assert surface_mask(img, img, (12, 0, 60, 10), 8.5) is not None
