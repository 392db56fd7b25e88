"""Neighbour tracks of one car seen as several: a far face broken into groups, duplicate tracks folded into one."""

from dataclasses import replace

import numpy as np
import pytest

from percept.neighbours import NeighbourTracker

from .test_tracker import DT, W, det


def test_a_far_car_whose_face_breaks_into_groups_is_one_track():
    rng = np.random.default_rng(3)
    tr = NeighbourTracker(DT)
    for k in range(45):
        x = -90.0 + 7.0 * k * DT  # closing at 7 m/s
        # two or three groups a frame, scattered by a few metres along the lane, as a car 80-90 m back gives
        parts = [det(x + float(rng.normal(0, 2.5)), W + float(rng.normal(0, 0.3)), 1.0) for _ in range(2 + k % 2)]
        tr.step({"rear": parts}, W)
    (t,) = [t for t in tr.tracks if t.confirmed]
    assert len(tr.tracks) == 1 and t.kf.x[0, 0] == pytest.approx(-90.0 + 7.0 * 44 * DT, abs=3.0)
    # two cars a lane apart stay two
    tr = NeighbourTracker(DT)
    for k in range(10):
        tr.step({"rear": [det(-80.0, W), det(-80.0, 0.0)]}, W)
    assert len(tr.tracks) == 2


def test_of_two_tracks_of_one_car_the_established_one_stays():
    tr = NeighbourTracker(DT)
    for _ in range(20):
        tr.step({"rear": [det(-16.0, W)]}, W)
    (old,) = tr.tracks
    # a young track of the same car, 1 m off across its lane, takes this frame's detection from the established one
    tr.tracks.append(replace(old, track_id=99, kf=tr._new_filter(det(-15.5, W - 1.0)), hits=2))
    tr.step({"rear": [det(-15.5, W - 1.0)]}, W)
    assert [t.track_id for t in tr.tracks] == [old.track_id]
