"""The road paint's compiled selection gives, bit for bit, what the same operations in numpy give.

The reference below is the numpy form: the visible road surface outlined from the road's samples, and the lane
paint pieces filtered for distance (dashes stretched into their period, thin lines widened, the alpha level). The
polygons handed to OpenCV must be the same, so that the frames are.
"""

import math

import numpy as np
import pytest
from highway_env.envs.racetrack_env import RacetrackEnv
from highway_env.road.road import RoadNetwork

from percept.sensors import Pose2D, StereoRig
from percept.sims.render.paint import (ALPHA_STEPS, FADE_M, MARKING_FAR_M, MIN_WIDTH_PX, SURFACE_FAR_M, RoadIndex,
                                       _marking_pieces, _surface_samples)
from percept.sims.render.raster import NEAR_M
from percept.sims.road_geometry import DASH_GAP_M, DASH_LENGTH_M, MARKING_WIDTH_M, build_road_geometry


def reference_surface(index: RoadIndex, pose: Pose2D, near_x_m: float):
    cv = pose.to_vehicle_xy(index.centre)
    r = index.radius
    sel = np.flatnonzero((cv[:, 0] > near_x_m - r) & (cv[:, 0] < SURFACE_FAR_M + r)
                         & (np.abs(cv[:, 1]) < SURFACE_FAR_M + r))
    mark = np.zeros(len(index.left) + 1, np.int32)
    np.add.at(mark, index.lo[sel], 1)
    np.add.at(mark, index.hi[sel] + 1, -1)
    idx = np.flatnonzero(np.cumsum(mark)[:-1] > 0)
    lv, rv = pose.to_vehicle_xy(index.left[idx]), pose.to_vehicle_xy(index.right[idx])
    keep = np.flatnonzero((lv[:, 0] > near_x_m) & (rv[:, 0] > near_x_m) & (lv[:, 0] < SURFACE_FAR_M)
                          & (np.abs(lv[:, 1]) < SURFACE_FAR_M))
    if len(keep) < 2:
        return np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0, int), np.zeros(0, bool)
    gi = idx[keep]
    strip = index.strip[gi]
    brk = (np.diff(gi) > 1) | (np.diff(strip) != 0)
    first, last = np.r_[True, brk], np.r_[brk, True]
    x = lv[keep, 0]
    step = np.where(x < 60.0, 1, np.where(x < 150.0, 4, 16))
    dec = np.flatnonzero((gi % step == 0) | first | last)
    return lv[keep[dec]], rv[keep[dec]], strip[dec], first[dec]


def reference_marks(index: RoadIndex, pose: Pose2D, rig: StereoRig):
    near = rig.mount_x_m + NEAR_M
    c = pose.to_vehicle_xy(index.quad_centre)
    close = np.flatnonzero((c[:, 0] > near) & (c[:, 0] < MARKING_FAR_M) & (np.abs(c[:, 1]) < MARKING_FAR_M))
    qv = pose.to_vehicle_xy(index.quads[close])
    ok = (qv[..., 0].min(axis=1) > near) & (qv[..., 0].max(axis=1) < MARKING_FAR_M)
    qv, sel = qv[ok], close[ok]
    cen = qv.mean(axis=1)
    dist = np.hypot(cen[:, 0], cen[:, 1])
    depth = np.maximum(cen[:, 0] - rig.mount_x_m, NEAR_M)
    r = np.where(index.dashed[sel], np.clip((dist - FADE_M[0]) / (FADE_M[1] - FADE_M[0]), 0, 1), 0.0)
    ext = 1.0 + r * (DASH_GAP_M / DASH_LENGTH_M)
    qv[:, 1] = qv[:, 0] + (qv[:, 1] - qv[:, 0]) * ext[:, None]
    qv[:, 2] = qv[:, 3] + (qv[:, 2] - qv[:, 3]) * ext[:, None]
    k = np.maximum(1.0, MIN_WIDTH_PX / (rig.camera.fx * MARKING_WIDTH_M / depth))
    for i, j in ((0, 3), (1, 2)):
        m = (qv[:, i] + qv[:, j]) / 2
        h = (qv[:, i] - qv[:, j]) / 2 * k[:, None]
        qv[:, i], qv[:, j] = m + h, m - h
    level = np.clip(np.round(ALPHA_STEPS / (ext * k)), 1, ALPHA_STEPS).astype(int)
    return qv, index.quad_color[sel], level


@pytest.mark.parametrize("network", ["straight", "racetrack"])
def test_the_compiled_road_paint_is_the_numpy_one(network):
    # four straight lanes, and highway-env's racetrack (curves of several radii, two lanes)
    net = RoadNetwork.straight_road_network(4, length=3000) if network == "straight" else RacetrackEnv().road.network
    index = RoadIndex(build_road_geometry(net))
    rig = StereoRig()
    near = rig.mount_x_m + NEAR_M
    rng = np.random.default_rng(4)
    seen = 0
    for _ in range(150):
        # somewhere on or near the road, facing anywhere
        k = rng.integers(len(index.centre))
        pose = Pose2D(index.centre[k, 0] + rng.normal(0, 10), index.centre[k, 1] + rng.normal(0, 4),
                      rng.uniform(-math.pi, math.pi))
        c, s = math.cos(pose.yaw_rad), math.sin(pose.yaw_rad)
        got = _surface_samples(index.left, index.right, index.strip, index.lo, index.hi, index.centre, index.radius,
                               pose.x_m, pose.y_m, c, s, near, SURFACE_FAR_M)
        # the compiled culls and their numpy references make the same float64 tests: the same samples to the bit
        for a, b in zip(got, reference_surface(index, pose, near)):
            assert np.array_equal(a, b)
        got = _marking_pieces(index.quads, index.quad_centre, index.dashed, index.quad_color, pose.x_m, pose.y_m, c,
                              s, near, MARKING_FAR_M, rig.mount_x_m, rig.camera.fx)
        for a, b in zip(got, reference_marks(index, pose, rig)):
            assert np.array_equal(a, b)
        seen += len(got[0]) > 0
    assert seen >= 50  # most poses see paint
