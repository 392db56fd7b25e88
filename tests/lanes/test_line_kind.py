"""Broken or solid boundaries, and the lane track moving to the lane beside as the car's centre crosses."""

import numpy as np
import pytest

from percept.lanes.line_kind import line_kind
from percept.lanes.tracker import LaneTracker
from percept.lanes.types import LaneFit
from percept.sensors import LaneEstimate


def painted(starts, length, step=0.25):
    """Ranges [m] of points on painted stretches of ``length`` beginning at ``starts``."""
    return np.concatenate([np.arange(s, s + length, step) for s in starts])


def test_dashes_are_broken_a_line_is_solid_even_when_a_car_hides_its_far_end():
    dashes = painted(np.arange(2.0, 60.0, 12.0), 3.0)  # 3 m dashes, 9 m gaps
    assert line_kind(dashes) is True
    assert line_kind(painted([6.0], 29.0)) is False
    assert line_kind(painted([6.0], 12.0)) is False  # a car 18 m ahead hides the rest: truncated, not broken
    assert line_kind(painted([6.0], 5.0)) is None  # too little seen
    assert line_kind(np.array([])) is None


def fit(offset, broken=(None, None), width=4.0, heading=0.0):
    est = LaneEstimate(offset, heading, 0.0, width, 1.0)
    return LaneFit(est, np.zeros(0), 0.02, 40, 40, np.diag([1e-4, 1e-6, 1e-10, 1e-12, 1e-4]), 0.0, broken)


def test_the_track_follows_the_cars_centre_into_the_lane_beside():
    t = LaneTracker(width_prior_m=4.0)
    for _ in range(10):
        t.update(fit(0.0, broken=(True, False)))
    assert t.estimate.beside == (True, False) and t.estimate.index == 0
    # the car moves 3 m to the left at 1.5 m/s (20 m/s, heading 0.075 rad); each frame's fit is of the lane the
    # track is on (the fit gates around it)
    for y in np.arange(0.1, 3.01, 0.1):
        t.predict(20.0, 0.0, 1 / 15)
        t.update(fit(y - 4.0 * t.estimate.index, heading=0.075))
    est = t.estimate
    # past the left boundary the lane beyond is tracked, its right boundary the broken line crossed
    assert est.index == 1 and est.offset_m == pytest.approx(3.0 - 4.0, abs=0.05)
    assert est.beside == (None, True)


def test_a_fresh_search_keeps_the_lane_count():
    t = LaneTracker()
    t.reset(index=3)
    assert t.estimate.index == 3 and t.estimate.beside == (None, None)
