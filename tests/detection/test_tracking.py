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
    assert tr.measure(box, agree, verify=True)[3] is True  # kept, and counted as the stereo pair's agreement
    assert tr.measure(box, behind, verify=True) is None
    assert tr.measure(box, lambda b, zg: None, verify=True) is None  # no stereo match: nothing confirms it
    assert tr.measure(box, None, verify=True) is None  # no right image
    assert tr.measure(box, behind)[3] is False  # a box that needs no verification is measured, not agreed with
    far_behind = lambda b, z_ground: (z_ground + 25.0, 3.0) if z_ground > 30.0 else (z_ground, 1.0)  # noqa: E731
    tracks = tr.update([box, person_box(rig, 20.0, 3.0)], [0.3, 1.0], stereo=far_behind, verify=[True, True])
    assert [round(t.position_m[1]) for t in tracks] == [3]


def test_stereo_agreements_are_counted_per_track():
    rig = StereoRig()
    tr = PersonTracker(rig, DT)
    agree = lambda b, z_ground: (z_ground, 0.5)  # noqa: E731
    for k in range(6):
        tr.predict(0.0)
        # the stereo pair agrees on every other frame, and finds nothing to match on the others
        tracks = tr.update([person_box(rig, 20.0, 2.0)], [1.0], stereo=agree if k % 2 else (lambda b, z: None))
    assert tracks[0].hits == 6 and tracks[0].stereo_hits == 3


def test_a_person_standing_beside_a_bend_is_not_taken_to_walk_while_the_ego_turns():
    # the ego drives a 150 m radius bend at 15 m/s (0.1 rad/s, turning left); a person stands still 30 m ahead: in
    # the vehicle frame they sweep to the right at up to 3 m/s, which is the ego's turn, not their walk
    rig = StereoRig()
    turning, straight = PersonTracker(rig, DT), PersonTracker(rig, DT)
    v, w = 15.0, 0.1
    ego, heading = np.zeros(2), 0.0
    person = np.array([30.0, 3.0])
    for _ in range(15):
        heading += w * DT
        ego = ego + v * DT * np.array([np.cos(heading - w * DT / 2), np.sin(heading - w * DT / 2)])
        c, s = np.cos(heading), np.sin(heading)
        x, y = np.array([[c, s], [-s, c]]) @ (person - ego)
        turning.predict(v, w)
        straight.predict(v)
        (t,) = turning.update([person_box(rig, x, y)], [1.0])
        (t_straight,) = straight.update([person_box(rig, x, y)], [1.0])
    assert x < 16.0 and abs(t.velocity_mps[1]) < 0.1 and abs(t.velocity_mps[0]) < 0.1, t
    assert t.position_m[1] == pytest.approx(y, abs=0.05)
    assert t_straight.velocity_mps[1] < -1.0  # the turn left out: a walk to the right


def test_a_coasting_track_stands_where_it_was_last_seen():
    rig = StereoRig()
    tr = PersonTracker(rig, DT)
    ego, x, y = 10.0, 30.0, 4.0
    for _ in range(6):  # six detections stepping left at 1.5 m/s: too few to trust as a walk
        tr.predict(ego)
        x, y = x - ego * DT, y - 1.5 * DT
        (t,) = tr.update([person_box(rig, x, y)], [1.0])
    seen = t.position_m
    for k in range(1, 9):  # then missed: the filter carries its speed on, the standing position only the ego's travel
        tr.predict(ego)
        (t,) = tr.update([], [])
        assert t.standing_m[0] == pytest.approx(seen[0] - ego * DT * k)
        assert t.standing_m[1] == pytest.approx(seen[1])
    assert t.position_m[1] < seen[1] - 0.3


def test_a_vehicle_corner_taken_for_a_person_shows_its_speed_in_the_free_motion():
    # highway seed 1 at night: a car's corner 35 m ahead in the next lane, read as a person, held its range for
    # 0.6 s while the ego drove at 26 m/s; the person filter read 1.9 m/s over the ground and the car braked hard
    rig = StereoRig()
    tr = PersonTracker(rig, DT)
    ego, lead = 26.0, 22.0
    x = 37.0
    for _ in range(8):
        tr.predict(ego)
        x += (lead - ego) * DT
        (t,) = tr.update([person_box(rig, x, 3.0)], [1.0])
    assert np.hypot(*t.velocity_mps) < 5.0  # the person filter's prior still holds it near a standstill
    assert t.free_speed_mps == pytest.approx(lead, abs=2.5)
    assert t.free_speed_mps - 2.5 * t.sigma_free_speed_mps > 8.0 and t.too_fast


def test_a_standing_person_approached_at_speed_is_not_given_a_vehicles_speed():
    rig = StereoRig()
    tr = PersonTracker(rig, DT)
    ego, x = 26.0, 45.0
    for k in range(12):
        tr.predict(ego)
        x -= ego * DT
        (t,) = tr.update([person_box(rig, x, 1.0)], [1.0])
        assert t.free_speed_mps - 2.5 * t.sigma_free_speed_mps < 8.0, (k, t)
    assert t.free_speed_mps < 1.0 and not t.too_fast


def test_one_detection_on_another_part_of_the_vehicle_does_not_make_it_a_person_again():
    # highway seed 1 at night: after 0.5 s of the corner at 21 m/s over the ground, one taller window on the same car
    # put its feet 16 m nearer; the free motion fell to 6.5 +- 2.2 m/s for that frame
    rig = StereoRig()
    tr = PersonTracker(rig, DT)
    x = 37.0
    for _ in range(8):
        tr.predict(26.0)
        x -= 4.0 * DT
        (t,) = tr.update([person_box(rig, x, 3.0)], [1.0])
    assert t.too_fast
    tr.predict(26.0)
    u0, v0, u1, v1 = person_box(rig, x, 3.0)
    (t,) = tr.update([(u0, v0, u1, v1 + 0.6 * (v1 - v0))], [1.0])
    assert t.hits == 9 and t.too_fast


def test_a_far_person_whose_first_ranges_run_ahead_is_a_person_again_once_clearly_slow():
    # crossing seed 2 in rain: far away the feet's row stayed put while the car closed in at 12 m/s; the person's
    # free motion read 11 +- 2 m/s, then settled at 1.4 +- 0.2 as the ranges caught up; a dismissal kept for good
    # ended in a collision
    rig = StereoRig()
    tr = PersonTracker(rig, DT)
    ego, x, bias = 14.0, 55.0, 0.0
    seen_fast = False
    for k in range(45):
        tr.predict(ego)
        x -= ego * DT
        # the range read stays put for 20 frames, then catches up at one and a half times the closing speed
        bias = bias + ego * DT if k < 20 else max(bias - 0.5 * ego * DT, 0.0)
        (t,) = tr.update([person_box(rig, x + bias, 5.0)], [1.0])
        seen_fast |= t.too_fast
    assert seen_fast and not t.too_fast and t.free_speed_mps < 2.0


def test_one_window_ten_metres_nearer_does_not_bring_a_vehicles_free_motion_to_a_standstill():
    # cut-in seed 17 at night: a car's corner at 36 m, 15 m/s over the ground, read as a person; one taller window on
    # the same car put its feet at 24 m (sigma 0.8 m), ~6 sigma from the free motion's prediction, which fell from
    # 14.8 +- 2.7 to 1.9 +- 1.0 m/s; the track was a person again and the car braked hard for it
    rig = StereoRig()
    tr = PersonTracker(rig, DT)
    ego, lead, x = 20.5, 15.0, 40.0
    for _ in range(14):
        tr.predict(ego)
        x += (lead - ego) * DT
        (t,) = tr.update([person_box(rig, x, 3.0)], [1.0])
    assert t.too_fast and x == pytest.approx(35.0, abs=0.5)
    tr.predict(ego)
    x += (lead - ego) * DT
    u0, v0, u1, _ = person_box(rig, x, 3.0)
    near = person_box(rig, x - 11.0, 3.0)
    (t,) = tr.update([(u0, v0, u1, near[3])], [1.0])
    assert t.free_speed_mps > 10.0 and t.too_fast
    for _ in range(3):  # and it keeps following the vehicle
        tr.predict(ego)
        x += (lead - ego) * DT
        (t,) = tr.update([person_box(rig, x, 3.0)], [1.0])
    assert t.free_speed_mps == pytest.approx(lead, abs=3.0) and t.too_fast


@pytest.mark.parametrize("yaw_rate", [0.0, 0.31, -0.07])
def test_the_ego_step_is_the_motion_model_each_track_built_for_itself(yaw_rate):
    """``EgoStep.of`` (made once a frame for every track, its arrays read-only) holds the matrices each track made
    with np.block, np.vstack and filterpy's white-noise covariance, bit for bit."""
    from filterpy.common import Q_discrete_white_noise

    from percept.detection.tracking import EgoStep

    speed, accel = 13.7, TrackConfig().accel_mps2
    th = yaw_rate * DT
    c, s = np.cos(th), np.sin(th)
    rt = np.array([[c, s], [-s, c]])
    want = dict(rt=rt, f=np.block([[rt, rt * DT], [np.zeros((2, 2)), rt]]), b=np.vstack([-rt, np.zeros((2, 2))]),
                q=Q_discrete_white_noise(2, DT, accel ** 2, block_size=2, order_by_dim=False),
                travel=speed * DT * np.array([np.cos(th / 2), np.sin(th / 2)]))
    step = EgoStep.of(DT, speed, yaw_rate, accel)
    for name, a in want.items():
        got = getattr(step, name)
        assert got.dtype == a.dtype and got.shape == a.shape and got.tobytes() == a.tobytes(), name
        assert got.flags.c_contiguous and not got.flags.writeable
