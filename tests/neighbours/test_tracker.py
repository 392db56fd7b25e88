"""Neighbour tracks on synthetic detections: speeds, the blind band, hand-over between the rigs, cut-in warnings."""

import numpy as np
import pytest

from percept.neighbours import Detection, NeighbourConfig, NeighbourSlot, NeighbourTracker, PointsConfig, TrackerConfig
from percept.sensors import EgoPath, StereoRig, Zone

DT = 1 / 15
W = 4.0


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
        return [next(self.dets)], np.zeros(0)


def test_a_neighbour_moving_over_is_flagged_before_it_crosses():
    slot = NeighbourSlot(StereoRig(), None, DT)
    # 30 m ahead in the left lane, then drifting right at 1 m/s from t = 1 s
    lat = [W] * 15 + [W - 1.0 * k * DT for k in range(1, 60)]
    slot.front = _FakeFinder([det(32.0, y) for y in lat])
    frame = type("F", (), {"dropped": False, "has_rear": False, "left_gray": None, "right_gray": None})()
    flagged_at, crossed_at = None, None
    for k, y in enumerate(lat):
        nb, _ = slot.step(frame, {EgoPath: EgoPath.straight(25.0)})
        cut = nb.cutting_in()
        if cut is not None and flagged_at is None:
            flagged_at = k
            assert cut.zone is Zone.AHEAD and cut.lane == 1 and cut.time_to_cross_s > 0
        if y <= W / 2 and crossed_at is None:
            crossed_at = k
    assert flagged_at is not None and crossed_at is not None
    assert (crossed_at - flagged_at) * DT >= 1.0
    assert NeighbourConfig().horizon_s >= 1.0


def test_bad_points_config_is_refused():
    from percept.neighbours import BandStereo

    with pytest.raises(ValueError, match="shrink must be 1 or 2"):
        BandStereo(StereoRig(), PointsConfig(shrink=3))
