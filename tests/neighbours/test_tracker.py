"""Neighbour tracks on synthetic detections: speeds, the blind band, hand-over between the rigs, cut-in warnings."""

from dataclasses import replace

import numpy as np
import pytest

from percept.neighbours import Detection, NeighbourConfig, NeighbourSlot, NeighbourTracker, PointsConfig, TrackerConfig
from percept.sensors import EgoPath, StereoRig, Zone

DT = 1 / 15
W = 4.0


FRONT_ONLY = type("F", (), {"dropped": False, "has_rear": False, "left_gray": None, "right_gray": None})()
"""A frame the slot's fake finders read: the forward pair only."""


def det(x: float, lat: float, sigma: float = 0.1) -> Detection:
    face = x - 2.5 if x > 0 else x + 2.5
    return Detection(x, lat, face, 1.8, (0, 0, 10, 10), 50, sigma)


def test_relative_speed_of_a_vehicle_closing_from_behind():
    tr = NeighbourTracker(DT)
    for k in range(60):
        tr.step({"rear": [det(-45.0 + 3.0 * k * DT, W)]}, W)
    (t,) = tr.tracks
    assert t.confirmed
    assert t.kf.x[1, 0] == pytest.approx(3.0, abs=0.1)


def test_blind_band_keeps_the_track_and_the_front_rig_takes_it_over():
    tr = NeighbourTracker(DT)
    cfg = TrackerConfig()
    x = -20.0
    ids = set()
    for k in range(int(12 / DT)):
        x += 2.0 * DT  # 2 m/s faster than the ego
        seen = {}
        if x < cfg.blind_behind_m:
            seen["rear"] = [det(x, W)]
        elif x > cfg.blind_ahead_m + 1.0:
            seen["front"] = [det(x, W)]
        tr.step(seen, W)
        confirmed = [t for t in tr.tracks if t.confirmed]
        if k > 5:
            # never absent while it is there
            assert len(confirmed) == 1
            ids.add(confirmed[0].track_id)
    assert len(ids) == 1  # one track from behind, through the band, to ahead


def test_a_vehicle_that_stops_beside_the_ego_stays_in_the_band():
    tr = NeighbourTracker(DT)
    for k in range(30):
        tr.step({"rear": [det(-12.0 + 4.0 * k * DT, -W)]}, W)
    for _ in range(int(20 / DT)):  # then unseen for 20 s
        tr.step({}, W)
    (t,) = tr.tracks
    assert TrackerConfig().blind_behind_m <= t.x <= TrackerConfig().blind_ahead_m


def test_a_false_detection_makes_no_track():
    tr = NeighbourTracker(DT)
    tr.step({"front": [det(30.0, 0.0)]}, W)
    for _ in range(5):
        tr.step({}, W)
    assert tr.tracks == []


class _FakeFinder:
    """Feeds the slot's tracker one synthetic detection per frame."""

    def __init__(self, dets):
        self.dets = iter(dets)

    def find(self, left, right, lane):
        d = next(self.dets)
        return ([] if d is None else [d]), np.zeros(0)


@pytest.mark.parametrize("x_m", [32.0, 66.0])
def test_a_neighbour_moving_over_is_flagged_before_it_crosses(x_m):
    slot = NeighbourSlot(StereoRig(), None, DT)
    # ahead in the left lane (near, and beyond the 60 m within which cut-ins are scored), then drifting right at
    # 1 m/s from t = 1 s
    lat = [W] * 15 + [W - 1.0 * k * DT for k in range(1, 60)]
    slot.front = _FakeFinder([det(x_m, y) for y in lat])
    flagged_at, crossed_at = None, None
    for k, y in enumerate(lat):
        nb, _ = slot.step(FRONT_ONLY, {EgoPath: EgoPath.straight(25.0)})
        cut = nb.cutting_in()
        if cut is not None and flagged_at is None:
            flagged_at = k
            assert cut.zone is Zone.AHEAD and cut.lane == 1 and cut.time_to_cross_s > 0
        if y <= W / 2 and crossed_at is None:
            crossed_at = k
    assert flagged_at is not None and crossed_at is not None
    assert (crossed_at - flagged_at) * DT >= 1.0
    assert NeighbourConfig().horizon_s >= 1.0
    # in the ego lane now, it stays flagged: a target until the lead's own slot takes it up
    cut = nb.cutting_in()
    assert cut is not None and cut.lane == 0 and cut.time_to_cross_s == 0.0


def test_something_found_on_one_frame_in_three_is_not_flagged():
    slot = NeighbourSlot(StereoRig(), None, DT)
    # settled in the lane beside, then the same motion as a car moving over, but found on a third of the frames
    lat = [W] * 30 + [W - 1.0 * k * DT for k in range(1, 60)]
    slot.front = _FakeFinder([det(32.0, y) if k < 30 or k % 3 == 0 else None for k, y in enumerate(lat)])
    for k in range(len(lat)):
        nb, _ = slot.step(FRONT_ONLY, {EgoPath: EgoPath.straight(25.0)})
        assert nb.cutting_in() is None
        if k == 29:  # a settled neighbour before it moves
            assert slot.tracker.tracks[0].settled >= TrackerConfig().min_settled
    (track,) = slot.tracker.tracks
    assert track.seen == 5 and slot.tracker.recent_frames == 15


def test_tracks_move_with_the_ego_into_the_next_lane():
    tr = NeighbourTracker(DT)
    for _ in range(5):
        tr.step({"front": [det(30.0, W + 0.2)]}, W)
    (t,) = tr.tracks
    assert t.lane == 1
    tr.shift_lanes(W)  # the ego moved one lane to the left
    assert t.lane == 0 and t.lat == pytest.approx(0.2, abs=0.05)


def test_a_face_far_away_is_placed_less_surely_across_the_lane():
    from percept.neighbours.clusters import VEHICLE_WIDTH_M
    from percept.neighbours.finder import EDGE_SIGMA_PX, RigFinder

    rig = StereoRig()
    finder = RigFinder(rig, 3.0, 90.0)
    whole = lambda x: replace(det(x, W), width_m=VEHICLE_WIDTH_M)
    near, far = finder.at_depth(whole(12.5)), finder.at_depth(whole(62.5))
    # sigma_l = Z sigma_u / f, Z the face's range from the camera
    cam_x = float(rig.camera_position()[0])
    edges = (60.0 - cam_x) * EDGE_SIGMA_PX / rig.camera.fx
    assert far.sigma_lat_m == pytest.approx(edges)
    assert near.sigma_lat_m < far.sigma_lat_m
    # a face seen over half its width: the half it lacks, (W_v - w) / 2, in quadrature
    half = finder.at_depth(replace(det(62.5, W), width_m=VEHICLE_WIDTH_M / 2))
    assert half.sigma_lat_m == pytest.approx(np.hypot(edges, VEHICLE_WIDTH_M / 4))


def test_a_lone_sideways_jump_of_a_face_barely_moves_the_track():
    tr = NeighbourTracker(DT)
    for k in range(30):
        tr.step({"front": [det(30.0, W)]}, W)
    tr.step({"front": [det(30.0, W - 1.3)]}, W)  # the face took in the car's side for a frame
    (t,) = tr.tracks
    assert abs(t.lat - W) < 0.3 and abs(t.kf.x[3, 0]) < 0.5
    # the same jump kept up is followed
    for k in range(20):
        tr.step({"front": [det(30.0, W - 1.3)]}, W)
    assert abs(t.lat - (W - 1.3)) < 0.2


def _pull_out(cfg: TrackerConfig) -> tuple[list[float], list[float], list[bool]]:
    """A car settled 12 m ahead in the left lane pulls out towards the ego lane, its lateral speed rising at
    3 m/s^2 to 1.8 m/s: (true lateral speeds, estimated ones, whether the track manoeuvres), a frame each from the
    pull-out's first."""
    tr = NeighbourTracker(DT, cfg)
    for _ in range(30):
        tr.step({"front": [det(12.0, W)]}, W)
    lat, speed, truth, est, veers = W, 0.0, [], [], []
    for _ in range(15):
        speed = min(speed + 3.0 * DT, 1.8)
        lat -= speed * DT
        tr.step({"front": [det(12.0, lat)]}, W)
        truth.append(-speed)
        est.append(float(tr.tracks[0].kf.x[3, 0]))
        veers.append(tr.manoeuvring(tr.tracks[0]))
    return truth, est, veers


def test_a_car_pulling_out_is_followed_sideways_once_its_innovations_say_it_manoeuvres():
    truth, est, veers = _pull_out(TrackerConfig())
    assert not veers[0] and any(veers[:8])
    # 0.73 s after it began, its lateral speed is read within a fifth of the truth
    assert est[10] == pytest.approx(truth[10], rel=0.2)
    # the filter without the manoeuvre's noise reads less than half of it
    truth, est_fixed, _ = _pull_out(replace(TrackerConfig(), manoeuvre_accel_noise_mps2=0.8))
    assert abs(est_fixed[10]) < 0.5 * abs(truth[10])


def test_a_lone_sideways_jump_is_no_manoeuvre():
    tr = NeighbourTracker(DT)
    for _ in range(30):
        tr.step({"front": [det(30.0, W)]}, W)
    tr.step({"front": [det(30.0, W - 1.3)]}, W)
    tr.step({"front": [det(30.0, W)]}, W)
    assert not tr.manoeuvring(tr.tracks[0]) and tr.tracks[0].veer == 0


def _held_track() -> NeighbourTracker:
    """A tracker with one track held in the blind band, beside the ego on the left, stopped at its front end (it
    came in from behind 4 m/s faster than the ego, and no rig saw it come out)."""
    tr = NeighbourTracker(DT)
    for k in range(30):
        tr.step({"rear": [det(-20.0 + 4.0 * k * DT, W)]}, W)
    for _ in range(90):
        tr.step({}, W)
    (t,) = tr.tracks
    assert t.blind_s > 0
    return tr


def test_a_lone_detection_farther_along_the_lane_does_not_carry_a_held_track_off():
    cfg = TrackerConfig()
    tr = _held_track()
    # a side seen alone 7.5 m beyond the band's end: within the gate of a track stopped at that end
    far = replace(det(cfg.blind_ahead_m + 7.5, W, sigma=2.5), cut_off=True)
    tr.step({"front": [far]}, W)
    tr.step({}, W)
    held = [t for t in tr.tracks if t.confirmed]
    assert len(held) == 1 and cfg.blind_behind_m <= held[0].x <= cfg.blind_ahead_m and held[0].blind_s > 0
    # seen three times in a row, it has come out
    for _ in range(cfg.confirm_hits):
        tr.step({"front": [far]}, W)
    assert held[0].blind_s == 0.0 and held[0].x > cfg.blind_ahead_m


def test_a_track_heading_for_the_band_coasts_unseen_from_its_fringe():
    cfg = TrackerConfig()
    tr = NeighbourTracker(DT)
    x = 36.0
    for _ in range(60):  # seen from 36 m down to 20 m ahead, 4 m/s slower than the ego
        tr.step({"front": [det(x, -W)]}, W)
        x -= 4.0 * DT
    for _ in range(int(3.0 / DT)):  # then unseen, more than max_misses frames, across the fringe into the band
        tr.step({}, W)
    (t,) = tr.tracks
    assert t.blind_s > 0 and cfg.blind_behind_m <= t.x <= cfg.blind_ahead_m
    # one moving away from the band is dropped
    tr = NeighbourTracker(DT)
    for k in range(60):
        tr.step({"front": [det(16.0 + 4.0 * k * DT, -W)]}, W)
    for _ in range(cfg.max_misses + 1):
        tr.step({}, W)
    assert tr.tracks == []


def test_a_car_last_seen_cut_off_in_the_fringe_is_held_in_the_band_when_it_vanishes():
    cfg = TrackerConfig()
    tr = NeighbourTracker(DT)
    x = cfg.blind_ahead_m + 1.0
    for _ in range(30):  # seen cut off at the front image's edge, read as drifting away from the band
        tr.step({"front": [replace(det(x, -W, sigma=2.0), cut_off=True)]}, W)
        x += 0.5 * DT
    for _ in range(cfg.max_misses + 1):  # then unseen: it has gone on into the band
        tr.step({}, W)
    (t,) = tr.tracks
    assert t.blind_s > 0 and cfg.blind_behind_m <= t.x <= cfg.blind_ahead_m
    # one read as heading into the band, however young, coasts on at its speed instead of stopping at its end
    tr = NeighbourTracker(DT)
    x = cfg.blind_ahead_m + 9.0
    for _ in range(cfg.min_settled - 2):
        tr.step({"front": [replace(det(x, -W, sigma=0.3), cut_off=True)]}, W)
        x -= 4.0 * DT
    for _ in range(int(1.0 / DT)):
        tr.step({}, W)
    (t,) = tr.tracks
    assert t.x == pytest.approx(x - 4.0 * (1.0 - DT), abs=0.5) and t.kf.x[1, 0] == pytest.approx(-4.0, abs=0.3)
    # a whole face in the same place that vanishes is lost, not held, and so is a young track cut off there (rain or a
    # guard rail matched by chance at the image's edge on a few frames)
    for frames, cut_off in ((30, False), (cfg.min_settled - 1, True)):
        tr = NeighbourTracker(DT)
        for k in range(frames):
            tr.step({"front": [replace(det(cfg.blind_ahead_m + 1.0 + 0.5 * k * DT, -W), cut_off=cut_off)]}, W)
        for _ in range(cfg.max_misses + 1):
            tr.step({}, W)
        assert tr.tracks == []


def test_bad_points_config_is_refused():
    from percept.neighbours import BandStereo

    with pytest.raises(ValueError, match="shrink must be 1 or 2"):
        BandStereo(StereoRig(), PointsConfig(shrink=3))
