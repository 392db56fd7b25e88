"""Tracking people on the ground plane from person boxes: confirmation, lateral speed, coasting, gating."""

import numpy as np
import pytest

from percept.detection import PersonTracker, TrackConfig
from percept.sensors import StereoRig

DT = 1 / 15


def person_box(rig: StereoRig, x: float, y: float, height: float = 1.75):
    """The person box a perfect detector would give for feet at (x, y) in the vehicle frame."""
    uv, _ = rig.project_vehicle_points(np.array([[x, y, 0.0], [x, y, height]]))
    h = uv[0, 1] - uv[1, 1]
    return (uv[0, 0] - 0.2 * h, uv[1, 1], uv[0, 0] + 0.2 * h, uv[0, 1])


def test_a_crossing_person_is_confirmed_and_its_walk_measured():
    rig = StereoRig()
    tr = PersonTracker(rig, DT)
    ego, x, y = 10.0, 40.0, -4.0
    for k in range(45):
        tr.predict(ego)
        x, y = x - ego * DT, y + 1.4 * DT  # a person walking left at 1.4 m/s while the ego closes at 10 m/s
        tracks = tr.update([person_box(rig, x, y)], [1.0])
        if k == 1:
            assert not tracks[0].confirmed
    (t,) = tracks
    assert t.confirmed and t.seen and t.hits == 45
    assert t.position_m[0] == pytest.approx(x, abs=0.3) and t.position_m[1] == pytest.approx(y, abs=0.1)
    assert t.velocity_mps[1] == pytest.approx(1.4, abs=0.2)
    assert abs(t.velocity_mps[0]) < 0.5  # the ego's own motion is not the person's
    assert t.height_m == pytest.approx(1.75, abs=0.05)


def test_tracks_coast_through_dropped_frames_and_die_after_misses():
    rig = StereoRig()
    cfg = TrackConfig()
    tr = PersonTracker(rig, DT, cfg)
    for _ in range(5):
        tr.predict(0.0)
        tr.update([person_box(rig, 20.0, 2.0)], [1.0])
    for _ in range(20):  # dropped frames: no detections and no misses
        tr.predict(0.0)
        tracks = tr.update([], [], seen=False)
    assert len(tracks) == 1 and tracks[0].misses == 0
    for k in range(cfg.max_misses + 1):
        tr.predict(0.0)
        tracks = tr.update([], [])
        if k == cfg.report_misses:
            assert tracks[0].confirmed and not tracks[0].seen  # coasting: acts, but is not reported as seen
    assert tracks == []


def test_two_people_keep_their_own_tracks_and_an_outlier_starts_a_new_one():
    rig = StereoRig()
    tr = PersonTracker(rig, DT)
    for _ in range(10):
        tr.predict(0.0)
        tracks = tr.update([person_box(rig, 15.0, -3.0), person_box(rig, 25.0, 3.0)], [1.0, 1.0])
    assert sorted(t.track_id for t in tracks) == [1, 2]
    tr.predict(0.0)
    tracks = tr.update([person_box(rig, 15.0, -3.0), person_box(rig, 25.0, 3.0), person_box(rig, 35.0, 0.0)],
                       [1.0, 1.0, 1.0])
    assert sorted(t.track_id for t in tracks) == [1, 2, 3]
    assert [t.confirmed for t in sorted(tracks, key=lambda t: t.track_id)] == [True, True, False]


def test_a_box_above_the_horizon_is_not_a_person_on_the_road():
    rig = StereoRig()
    tr = PersonTracker(rig, DT)
    v_h = rig.horizon_row
    assert tr.measure((300.0, v_h - 80, 330.0, v_h - 10)) is None
    assert tr.update([(300.0, v_h - 80, 330.0, v_h - 10)], [1.0]) == []


def test_a_box_to_verify_is_kept_only_where_its_stereo_depth_agrees_with_its_ground_contact():
    rig = StereoRig()
    tr = PersonTracker(rig, DT)
    box = person_box(rig, 35.0, 0.0)
    z = 35.0 - tr.cam_x
    agree = lambda b, z_ground: (z + 0.5, 1.5)  # noqa: E731
    behind = lambda b, z_ground: (z + 25.0, 3.0)  # noqa: E731  (the scenery behind, not a person standing there)
    assert tr.measure(box, agree, verify=True) is not None
    assert tr.measure(box, behind, verify=True) is None
    assert tr.measure(box, lambda b, zg: None, verify=True) is None  # no stereo match: nothing confirms it
    assert tr.measure(box, None, verify=True) is None  # no right image
    assert tr.measure(box, behind) is not None  # a box that needs no verification is measured as before
    far_behind = lambda b, z_ground: (z_ground + 25.0, 3.0) if z_ground > 30.0 else (z_ground, 1.0)  # noqa: E731
    tracks = tr.update([box, person_box(rig, 20.0, 3.0)], [0.3, 1.0], stereo=far_behind, verify=[True, True])
    assert [round(t.position_m[1]) for t in tracks] == [3]
