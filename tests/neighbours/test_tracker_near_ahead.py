"""A car in the ego lane too near for the front rig to find: an established track is held there by prediction, no
nearer than touching, for ``TrackerConfig.near_hold_s``, and taken over when the rig finds it again."""

import pytest

from percept.neighbours import NeighbourTracker, TrackerConfig

from .test_tracker import DT, W, det

TOUCHING_M = 5.0  # the centre of a car touching the ego's front bumper, both 5 m long [m]


def _closing_then_unseen(tr: NeighbourTracker, frames_seen: int) -> float:
    """A car closing at 3 m/s in the ego lane, found on ``frames_seen`` frames up to 8.5 m ahead; its last x [m]."""
    x = 8.5 + 3.0 * DT * (frames_seen - 1)
    for _ in range(frames_seen):
        tr.step({"front": [det(x, 0.5)]}, W)
        x -= 3.0 * DT
    return x + 3.0 * DT


def test_an_established_car_too_near_to_see_is_held_no_nearer_than_touching_then_dropped():
    cfg = TrackerConfig()
    tr = NeighbourTracker(DT, cfg)
    _closing_then_unseen(tr, 30)
    held = 0
    while tr.tracks:
        tr.step({}, W)
        if tr.tracks:
            (t,) = tr.tracks
            assert t.x >= TOUCHING_M - 1e-9
            assert abs(t.lat - 0.5) < 0.1  # it keeps its lateral place
            held += 1
    # held for near_hold_s, then max_misses frames more before it is dropped
    assert held == pytest.approx(cfg.near_hold_s / DT + cfg.max_misses, abs=1)


def test_a_held_car_is_taken_over_when_the_gap_opens():
    tr = NeighbourTracker(DT)
    _closing_then_unseen(tr, 30)
    for _ in range(15):
        tr.step({}, W)
    (held,) = tr.tracks
    for k in range(10):  # the ego braked: the car is found again, pulling away
        tr.step({"front": [det(7.5 + 2.0 * k * DT, 0.5)]}, W)
    (t,) = tr.tracks
    assert t.track_id == held.track_id
    assert t.blind_s == 0.0


def test_a_young_track_near_ahead_is_not_held():
    cfg = TrackerConfig()
    tr = NeighbourTracker(DT, cfg)
    _closing_then_unseen(tr, cfg.min_settled - 1)
    for _ in range(cfg.max_misses + 1):
        tr.step({}, W)
    assert tr.tracks == []


def test_a_car_behind_in_the_ego_lane_is_not_held_ahead():
    cfg = TrackerConfig()
    tr = NeighbourTracker(DT, cfg)
    for _ in range(30):
        tr.step({"rear": [det(-30.0, 0.0)]}, W)
    for _ in range(cfg.max_misses):
        tr.step({}, W)
        (t,) = tr.tracks
        assert t.x < 0.0 and t.blind_s == 0.0
    tr.step({}, W)
    assert tr.tracks == []


def test_a_held_car_pulling_away_stays_held_at_the_near_range_edge():
    # a car pulling away at 1.5 m/s, found up to 7.8 m ahead, then unseen: its prediction reaches near_ahead_m and
    # stops there, held for near_hold_s like a car closing, not dropped after max_misses
    cfg = TrackerConfig()
    tr = NeighbourTracker(DT, cfg)
    for k in range(20):
        tr.step({"front": [det(5.9 + 1.5 * k * DT, 0.5)]}, W)
    held = 0
    while tr.tracks:
        tr.step({}, W)
        if tr.tracks:
            (t,) = tr.tracks
            assert t.x <= cfg.near_ahead_m + 1.5 * DT * cfg.max_misses
            held += 1
    assert held == pytest.approx(cfg.near_hold_s / DT + cfg.max_misses, abs=1)


def test_a_car_held_beside_behind_the_ego_that_moves_into_its_lane_is_not_held_ahead():
    # a car flagged as cutting in, held in the blind band 6 m behind the ego's centre, moves on into the ego lane
    # unseen: it is not a car near ahead, and is not put ahead of the ego's bumper
    cfg = TrackerConfig()
    tr = NeighbourTracker(DT, cfg)
    for k in range(30):
        tr.step({"rear": [det(-16.0 + 3.0 * k * DT, -W)]}, W)
    for _ in range(40):
        tr.step({}, W)
    (t,) = tr.tracks
    assert t.blind_s > 0 and t.x < 0.0
    t.warning = True
    t.kf.x[2, 0], t.kf.x[3, 0] = -0.3, 0.0  # now in the ego lane
    tr.step({}, W)
    assert all(u.x < 0.0 for u in tr.tracks)
