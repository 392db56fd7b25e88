"""The finder's compiled group search against numpy's formulas: the same group, bit for bit, on synthetic
standing pixels (blobs at several ranges, scattered strays, blobs of equal area)."""

import cv2
import numpy as np
import pytest

from percept.longitudinal.groups import first_grounded_blob, group_extent, range_bins
from percept.longitudinal.obstacles import Obstacle, ObstacleFinder
from percept.longitudinal.quantiles import median, percentile, percentiles
from percept.sensors import StereoRig


def _numpy_nearest_group(finder, u, v, z, pv, area):
    """``ObstacleFinder.nearest_group`` in numpy's operations, without the kernels."""
    cfg, cam = finder.cfg, finder.rig.camera
    k = np.floor(np.log(z) / np.log1p(cfg.bin_rel)).astype(int)
    order = np.argsort(k, kind="stable")
    ks = k[order]
    run = np.concatenate([[0.0], np.cumsum(area[order], dtype=np.float64)])
    bins = np.unique(ks)
    los, his = np.searchsorted(ks, bins - 1, "left"), np.searchsorted(ks, bins + 1, "right")
    needs = np.maximum(cfg.min_area_m2 * (cam.fx / np.exp(bins * np.log1p(cfg.bin_rel))) ** 2, 24)
    for i in np.flatnonzero(run[his] - run[los] >= needs * (1 - 1e-4)):
        lo, hi, need = los[i], his[i], needs[i]
        near = np.sort(order[lo:hi])
        if area[near].sum() < need:
            continue
        uu, vv, aa = u[near], v[near], area[near]
        cell = cfg.blob_cell_px
        cu, cv_ = (uu / cell).astype(int), (vv / cell).astype(int)
        grid = np.zeros((int(cv_.max()) + 2, int(cu.max()) + 2), np.uint8)
        grid[cv_, cu] = 1
        n, labels = cv2.connectedComponents(grid, connectivity=8)
        lab = labels[cv_, cu]
        best = int(np.argmax(np.bincount(lab, weights=aa, minlength=n)[1:])) + 1
        blob = near[np.flatnonzero(lab == best)]
        if area[blob].sum() >= need and percentile(pv[blob, 2], 5) < cfg.grounded_m:
            break
    else:
        return None
    u0, u1 = percentiles(u[blob], (2, 98))
    v0, v1 = percentiles(v[blob], (2, 98))
    box = (int(max(u0 - 1, 0)), int(max(v0 - 1, 0)), int(min(u1 + 2, cam.width)), int(min(v1 + 2, cam.height)))
    return Obstacle(float(median(z[blob])), box, float(area[blob].sum()))


def _scene(rng, blobs, strays, equal=False):
    """Standing pixels: ``blobs`` solid patches at random ranges (all of one size and range when ``equal``), and
    ``strays`` scattered ones; (u, v, z, points, area) as the finder hands them over."""
    us, vs, zs, hs = [], [], [], []
    z_equal = rng.uniform(8, 40)
    for _ in range(blobs):
        z = z_equal if equal else rng.uniform(5, 60)
        w, h = (20, 12) if equal else (int(rng.integers(4, 60)), int(rng.integers(4, 40)))
        u0, v0 = rng.integers(0, 560), rng.integers(150, 400)
        gu, gv = np.meshgrid(np.arange(w) * 2 + 0.5, np.arange(h) * 2 + 0.5)
        us.append(u0 + gu.ravel()), vs.append(v0 + gv.ravel())
        zs.append(z + rng.normal(0, 0.02 * z, gu.size) * (not equal))
        hs.append(rng.uniform(-0.2, 1.5, gu.size) if not equal else np.full(gu.size, 0.5))
    us.append(rng.uniform(0, 639, strays)), vs.append(rng.uniform(100, 479, strays))
    zs.append(rng.uniform(3, 99, strays)), hs.append(rng.uniform(0.3, 3.5, strays))
    u, v, z = (np.concatenate(a).astype(np.float32) for a in (us, vs, zs))
    pv = np.column_stack([z + 0.8, np.zeros_like(z), np.concatenate(hs)]).astype(np.float64)
    area = np.where(rng.random(len(u)) < 0.5, 4.0, 16.0).astype(np.float32) if not equal else np.full(len(u), 4.0,
                                                                                                        np.float32)
    return u, v, z, pv, area


@pytest.fixture(scope="module")
def finder():
    return ObstacleFinder(StereoRig())


@pytest.mark.parametrize("seed", range(40))
def test_nearest_group_equals_numpys(finder, seed):
    rng = np.random.default_rng(seed)
    scene = _scene(rng, blobs=int(rng.integers(1, 6)), strays=int(rng.integers(0, 400)), equal=seed % 5 == 0)
    assert finder.nearest_group(*scene) == _numpy_nearest_group(finder, *scene)


def test_range_bins_equal_numpys():
    rng = np.random.default_rng(3)
    k = rng.integers(40, 120, 2000)
    area = rng.choice(np.array([4.0, 16.0], np.float32), 2000)
    order, run, bins, los, his = range_bins(k, area)
    want_order = np.argsort(k, kind="stable")
    ks = k[want_order]
    assert np.array_equal(order, want_order) and np.array_equal(bins, np.unique(ks))
    assert run.tobytes() == np.concatenate([[0.0], np.cumsum(area[want_order], dtype=np.float64)]).tobytes()
    assert np.array_equal(los, np.searchsorted(ks, bins - 1, "left"))
    assert np.array_equal(his, np.searchsorted(ks, bins + 1, "right"))


def test_two_blobs_of_one_area_are_left_to_the_caller():
    # two solid 3 x 3-cell blobs far apart, one bin: the kernel cannot say which cv2 labels first
    g = np.arange(0, 24, 2, dtype=np.float32) + 0.5
    gu, gv = np.meshgrid(g, g)
    u = np.concatenate([gu.ravel(), gu.ravel() + 300]).astype(np.float32)
    v = np.concatenate([gv.ravel(), gv.ravel()]).astype(np.float32) + 200
    n = len(u)
    order = np.arange(n, dtype=np.int64)
    args = (np.zeros(1, np.int64), np.zeros(1, np.int64), np.array([n], np.int64), np.array([100.0]), order, u, v,
            np.zeros(n), np.full(n, 4, np.float32), 8, 5, 1.0)
    found, blob = first_grounded_blob(*args)
    assert found == -1 and len(blob) == 0
    # one more pixel on the second: it is the largest
    u, v = np.append(u, 320.5).astype(np.float32), np.append(v, 200.5).astype(np.float32)
    args = (args[0], args[1], np.array([n + 1]), args[3], np.arange(n + 1), u, v, np.zeros(n + 1),
            np.full(n + 1, 4, np.float32), 8, 5, 1.0)
    found, blob = first_grounded_blob(*args)
    assert found == 1 and np.array_equal(blob, np.arange(n // 2, n + 1))


def test_group_extent_equals_numpys_bit_for_bit():
    rng = np.random.default_rng(9)
    for n in list(range(1, 12)) + [50, 51, 300]:
        for _ in range(30):
            u = (rng.integers(0, 320, 400) * 2 + 0.5).astype(np.float32)  # pixel centres: many ties
            v = rng.uniform(0, 480, 400).astype(np.float32)
            z = rng.uniform(3, 99, 400).astype(np.float32)
            area = rng.choice(np.array([4.0, 16.0], np.float32), 400)
            blob = np.sort(rng.choice(400, n, replace=False)).astype(np.int64)
            got = group_extent(u, v, z, area, blob)
            want = (*np.percentile(u[blob], [2, 98]), *np.percentile(v[blob], [2, 98]), np.median(z[blob]),
                    area[blob].sum())
            # (the kernel's float32 results come back as Python floats: the same values, widened)
            assert [float(g).hex() for g in got] == [float(w).hex() for w in want]
