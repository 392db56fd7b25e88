"""Faces the matcher cannot place nearer than they are: one at its nearest depth (``Detection.near_limit``), or a
sliver close by, bounds the car's range from above only, so a track nearer than such a reading stays near; read
nearer than the track, it is taken as it is."""

from dataclasses import replace

import pytest

from percept.neighbours import NeighbourTracker, PointsConfig, TrackerConfig
from percept.neighbours.finder import NEAR_LIMIT_MARGIN_M, RigFinder
from percept.sensors import StereoRig

from .test_tracker import DT, det

TRUE_X = 12.0 - 3.0 * 29 * DT
"""The car's centre on the last frame of ``_closing`` [m]."""


def _closing(reading) -> NeighbourTracker:
    """A tracker following a car in the ego lane from 12 m, closing at 3 m/s for 2 s to 6 m, whose detections over
    the last second are ``reading(x)`` for its true centre x [m]."""
    tr = NeighbourTracker(DT)
    for k in range(30):
        x = 12.0 - 3.0 * k * DT
        tr.step({"front": [det(x, 0.0) if k < 15 else reading(x)]}, 4.0)
    return tr


def _long(x: float, **flags):
    """The car at centre x [m] read 2 m farther, with ``flags`` set on its detection."""
    return replace(det(x + 2.0, 0.0, sigma=0.03), **flags)


@pytest.mark.parametrize("flags", [{"near_limit": True}, {"width_m": 0.4}], ids=["near-limit", "sliver"])
def test_a_car_read_too_far_at_the_near_limit_or_as_a_sliver_close_by_stays_near(flags):
    (t,) = _closing(lambda x: _long(x, **flags)).tracks
    # a second of readings 2 m long moves it by under a third of that ...
    assert abs(t.x - TRUE_X) < 2.0 / 3
    # ... while a whole face read as long drags the track most of the way
    (plain,) = _closing(_long).tracks
    assert plain.x - TRUE_X > 1.5


def test_a_sliver_farther_away_is_taken_as_it_is():
    tr = NeighbourTracker(DT)
    far = TrackerConfig().near_sliver_m + 10.0
    for _ in range(30):
        tr.step({"front": [det(far, 0.0)]}, 4.0)
    for _ in range(15):
        tr.step({"front": [replace(det(far + 2.0, 0.0, sigma=0.03), width_m=0.4)]}, 4.0)
    (t,) = tr.tracks
    assert t.x > far + 1.5


def test_a_near_limit_face_nearer_than_the_track_pulls_it_in():
    (t,) = _closing(lambda x: replace(det(x - 1.0, 0.0, sigma=0.03), near_limit=True)).tracks
    assert t.x < TRUE_X - 0.7


def test_the_finder_flags_faces_at_its_nearest_depth():
    rig = StereoRig()
    finder = RigFinder(rig, 3.0, 90.0)
    cam_x = float(rig.camera_position()[0])
    # camera depth of the face = face_x - cam_x; the limit is near_m + NEAR_LIMIT_MARGIN_M
    limit = cam_x + PointsConfig().near_m + NEAR_LIMIT_MARGIN_M
    at = finder.at_depth(replace(det(0.0, 0.0), face_x_m=limit - 0.1))
    beyond = finder.at_depth(replace(det(0.0, 0.0), face_x_m=limit + 0.1))
    assert at.near_limit and not beyond.near_limit
