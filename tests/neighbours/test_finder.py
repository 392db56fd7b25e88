"""The finder's geometry on synthetic detections and points: a car seen past a nearer one, and groups too wide to be
one vehicle."""

from dataclasses import replace

import numpy as np
import pytest

from percept.neighbours import Detection, find_vehicles
from percept.neighbours.clusters import VEHICLE_WIDTH_M, Face
from percept.neighbours.finder import RigFinder
from percept.neighbours.points import StandingPoints
from percept.sensors import StereoRig

W = 3.75


def face(x: float, lat: float, width: float) -> Detection:
    """A car ahead whose face at x [m] is seen from lat - width / 2 to lat + width / 2 [m]."""
    return Detection(x + 2.5, lat, x, width, (0, 0, 10, 10), 200, 0.1)


def test_a_car_seen_past_a_nearer_one_is_centred_from_its_free_edge():
    finder = RigFinder(StereoRig(), 3.0, 90.0)
    # a car 40 m ahead in the left lane whose outer part hides behind one 25 m ahead in that lane: only its inner
    # 0.6 m is seen, from its inner edge W - W_v / 2
    inner = W - VEHICLE_WIDTH_M / 2
    far, near = face(40.0, inner + 0.3, 0.6), face(25.0, W, VEHICLE_WIDTH_M)
    shadows = lambda *dets: [finder.shadow(d) for d in dets]
    placed = finder.occluded(far, shadows(near, far))
    # centre = the free (inner) edge + W_v / 2
    assert placed.lat_m == pytest.approx(W)
    # nothing nearer: the part seen stays where it is; a whole face is never moved
    assert finder.occluded(far, shadows(far)).lat_m == far.lat_m
    whole = face(40.0, W, VEHICLE_WIDTH_M)
    assert finder.occluded(whole, shadows(near, whole)) is whole


def _slab(x: float, y0: float, y1: float) -> StandingPoints:
    """Points standing on a slab across the lane at x [m], from y0 to y1 [m], 0.4-1.4 m high."""
    y, z = np.meshgrid(np.arange(y0, y1, 0.05), np.arange(0.4, 1.4, 0.1))
    n = y.size
    f = lambda a: np.asarray(a, np.float32).ravel()
    return StandingPoints(f(np.arange(n) % 640), f(np.full(n, 240)), f(np.full(n, 10.0)), f(np.full(n, x)),
                          f(y), f(z))


@pytest.mark.parametrize("y0, y1, found", [(-1.0, 1.0, 1), (-4.0, 4.0, 0)])
def test_a_group_wider_than_any_vehicle_is_none(y0, y1, found):
    pts = _slab(20.0, y0, y1)
    measure = lambda p, idx, group: Face(20.0, 0.1, (float(p.y[group].min()), float(p.y[group].max())))
    dets = find_vehicles(pts, None, 3.0, 90.0, measure)
    assert len(dets) == found
    if found:
        assert dets[0].lat_m == pytest.approx(0.5 * (y0 + y1 - 0.05), abs=0.05)


def test_a_face_is_placed_across_the_lane_at_its_refined_range():
    finder = RigFinder(StereoRig(), 3.0, 90.0)
    c = finder.cam
    # points seen at 10 % more disparity than the face's refined one lie nearer along their rays than they are:
    # at the refined range, p = c + (p_i - c) d_i / d
    pts = _slab(40.0, 2.75, 4.75)
    d = float(pts.d[0]) / 1.1
    lo, hi = finder._lateral_extent(pts, np.arange(len(pts)), float(pts.d[0]), 0.5, d)
    y = c[1] + (np.quantile(pts.y, [0.05, 0.95]) - c[1]) * 1.1
    assert (lo, hi) == pytest.approx(tuple(y), abs=1e-4)
    # too few points at the face's disparity: no extent
    assert finder._lateral_extent(pts, np.arange(5), float(pts.d[0]), 0.5, d) is None


def test_a_group_too_wide_with_speckles_is_grouped_again_without_them():
    # a car and, joined to it, speckles across the road (fewer points than the car's)
    car, noise = _slab(20.0, -1.0, 1.0), _slab(19.0, -4.0, 4.0)
    pts = StandingPoints(*(np.concatenate([getattr(car, k), getattr(noise, k)[::8]]) for k in "uvdxyz"))
    flags = np.r_[np.zeros(len(car), bool), np.ones(len(pts) - len(car), bool)]
    measure = lambda p, idx, group: Face(20.0, 0.1, (float(p.y[group].min()), float(p.y[group].max())))
    assert find_vehicles(pts, None, 3.0, 90.0, measure) == []
    (found,) = find_vehicles(replace(pts, speckle=flags), None, 3.0, 90.0, measure)
    assert found.lat_m == pytest.approx(0.0, abs=0.05)
    # mostly speckles: noise, and what is left of it would be noise too
    mostly = StandingPoints(*(np.concatenate([getattr(car, k), getattr(noise, k)]) for k in "uvdxyz"))
    assert find_vehicles(replace(mostly, speckle=np.r_[flags[:len(car)], np.ones(len(noise), bool)]), None, 3.0,
                         90.0, measure) == []
