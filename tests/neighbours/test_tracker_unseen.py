"""Neighbour tracks a rig does not see on a frame: what they keep of their lateral speed, and how the ego's own
braking moves a car cutting in."""

from dataclasses import replace

import pytest

from percept.neighbours import NeighbourTracker

from .test_tracker import DT, W, det


def test_a_car_pulling_out_in_the_band_missed_on_one_frame_in_three_keeps_its_lateral_speed_while_it_manoeuvres():
    tr = NeighbourTracker(DT)
    # 10 m ahead in the lane to the right (inside the band), settled, then pulling out left at 2 m/s, found by the
    # front rig on two frames in three (rain)
    for k in range(30):
        tr.step({"front": [det(10.0, -W)]}, W)
    for k in range(1, 10):  # the last frame a miss
        tr.step({"front": [det(10.0, -W + 2.0 * k * DT)] if k % 3 else []}, W)
    (t,) = tr.tracks
    # a miss that reset its lateral speed to rest would leave it at 0; it manoeuvres, so the speed is kept
    assert tr.manoeuvring(t) and float(t.kf.x[3, 0]) > 1.2


@pytest.mark.parametrize("warned", [True, False])
def test_a_braking_ego_moves_the_relative_speed_of_a_car_cutting_in_it_no_longer_sees(warned):
    # a car 20 m ahead at the ego's speed, 25 m/s; then unseen for 4 frames while the ego brakes at 8 m/s^2: flagged as
    # cutting in (what the ego brakes for), it keeps its speed over the ground and pulls ahead at 8 m/s^2 relative to
    # the ego; any other neighbour is taken to slow with the ego
    tr = NeighbourTracker(DT)
    for _ in range(30):
        tr.step({"front": [det(20.0, -W)]}, W, 25.0)
    (t,) = tr.tracks
    t.warning = warned
    x0 = t.x
    for k in range(1, 5):
        tr.step({}, W, 25.0 - 8.0 * DT * k)
    # x' = 8 t, x = x0 + 8 t^2 / 2 after t = 4 frames
    assert t.kf.x[1, 0] == pytest.approx(8.0 * 4 * DT if warned else 0.0, abs=0.05)
    assert t.x - x0 == pytest.approx(4.0 * (4 * DT) ** 2 if warned else 0.0, abs=0.02)


@pytest.mark.parametrize("warned", [True, False])
def test_a_held_car_flagged_as_cutting_in_goes_on_moving_over_unseen(warned):
    # pulling out left at 2 m/s 10 m ahead in the lane to the right (inside the band), then unseen for 6 frames (0.4 s,
    # beyond lateral_coast_s): flagged as cutting in, it keeps its lateral speed; not flagged, it stops sideways
    tr = NeighbourTracker(DT)
    for k in range(30):
        tr.step({"front": [det(10.0, -W)]}, W)
    for k in range(1, 10):
        tr.step({"front": [det(10.0, -W + 2.0 * k * DT)]}, W)
    (t,) = tr.tracks
    t.warning = warned
    for _ in range(6):
        tr.step({}, W)
    assert t.blind_s > 0
    assert (float(t.kf.x[3, 0]) > 1.2) if warned else float(t.kf.x[3, 0]) == 0.0


@pytest.mark.parametrize("found, undone", [([1, 1, 0], True), ([1, 0, 1, 0, 1, 1, 0], True), ([1, 1, 1, 0], False)])
def test_a_takeover_not_confirmed_leaves_the_held_track_where_it_was(found, undone):
    # a car settled in the lane to the left comes alongside from ahead, 3 m/s slower, and is held in the band; a rig
    # then finds something 1.2 m farther out near the band's rear end, cut off by its image's edge (``found``: on which
    # frames): found on fewer than confirm_hits frames in a row, however often, the takeover is undone and the track
    # keeps its lane and lateral place; on 3 it is the car come out of the band and the track follows it
    tr = NeighbourTracker(DT)
    for k in range(60):
        tr.step({"front": [det(20.0 - 3.0 * k * DT, W)]}, W)
    for _ in range(150):  # 10 s: it falls back to the band's rear end and stops there
        tr.step({}, W)
    (t,) = tr.tracks
    assert t.blind_s > 0 and t.x == tr.cfg.blind_behind_m and t.lat == pytest.approx(W, abs=0.05)
    stray = replace(det(-15.0, W + 1.2), cut_off=True)
    for f in found:
        tr.step({"rear": [stray] if f else []}, W)
    (t,) = tr.tracks
    if undone:
        assert t.blind_s > 0 and t.lat == pytest.approx(W, abs=0.05) and t.lane == 1
    else:
        assert t.lat > W + 0.5
