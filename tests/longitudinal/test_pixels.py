"""The short projection of road points gives the rig's whole pixels: the same rows and far-band columns."""

import math

import numpy as np
import pytest

from percept.longitudinal.contact import ContactRange
from percept.longitudinal.obstacles import ObstacleFinder
from percept.longitudinal.pixels import TOL_PX, RoadPixels, clear, whole
from percept.sensors import EgoPath, LaneEstimate, StereoRig


@pytest.mark.parametrize("pitch", [0.0, 0.02, -0.03])
def test_short_projection_is_the_rigs_to_rounding(pitch):
    rig = StereoRig(pitch_rad=pitch)
    road = RoadPixels(rig)
    rng = np.random.default_rng(1)
    x, y = rng.uniform(3, 150, 500), rng.uniform(-20, 20, 500)
    uv, _ = rig.project_vehicle_points(np.column_stack([x, y, np.zeros_like(x)]))
    assert np.max(np.abs(road.columns(x, y) - uv[:, 0])) < TOL_PX / 100
    uv, _ = rig.project_vehicle_points(np.column_stack([x, np.zeros_like(x), np.zeros_like(x)]))
    assert max(abs(road.row(a) - b) for a, b in zip(x, uv[:, 1])) < TOL_PX / 100
    # behind the camera: no short value, so the rig's decides
    assert math.isnan(road.row(rig.mount_x_m - 1.0)) and np.isnan(road.columns(np.array([0.0]), np.array([0.0])))[0]


def test_a_value_at_a_whole_number_is_the_rigs():
    assert whole(3.2, math.floor, lambda: 99.0) == 3
    assert whole(3.0 + TOL_PX / 2, math.floor, lambda: 2.9999999999) == 2
    assert whole(math.nan, math.ceil, lambda: 4.5) == 5
    assert not clear(7.0) and not clear(math.inf) and clear(7.5)


@pytest.mark.parametrize("pitch", [0.0, 0.02])
def test_contact_rows_and_far_columns_are_the_rigs(pitch):
    rig = StereoRig(pitch_rad=pitch)
    finder, contact = ObstacleFinder(rig), ContactRange(rig)
    rng = np.random.default_rng(2)
    for _ in range(300):
        lane = LaneEstimate(rng.normal(0, 1), rng.normal(0, 0.05), rng.normal(0, 0.005), 3.5, 1.0,
                            curvature_rate_1pm2=rng.choice([0.0, rng.normal(0, 1e-4)]))
        path = EgoPath(lane, 20.0)
        (u0, u1), (r0, r1) = finder._far_columns(path), finder._rig_far_columns(path.centre_y(finder.x_far))
        s = finder.far.s
        assert (math.floor(u0 * s), math.ceil(u1 * s)) == (math.floor(r0 * s), math.ceil(r1 * s))
        z = rng.uniform(3, 100)
        assert whole(contact.road.row(contact.cam_x + z), math.floor, lambda: math.nan) == math.floor(contact._row(z))
        assert whole(contact.road.row(contact.cam_x + z), math.ceil, lambda: math.nan) == math.ceil(contact._row(z))
