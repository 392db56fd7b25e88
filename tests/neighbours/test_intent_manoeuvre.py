"""Cut-in warnings for a car pulling out close ahead: the manoeuvre its filter's innovations detect stands in for the
lateral speed's significance, which the manoeuvre's own process noise widens just as the car starts over; and a car
whose face only jitters across its lane is never flagged."""

import numpy as np

from percept.neighbours import NeighbourConfig, NeighbourSlot
from percept.neighbours.clusters import DEFAULT_LANE_WIDTH_M
from percept.sensors import EgoPath, StereoRig

from .test_tracker import DT, FRONT_ONLY, _FakeFinder, det

W = DEFAULT_LANE_WIDTH_M
"""The lane width the slot takes without a lane estimate [m]."""


def _pull_out() -> tuple[int, int, list]:
    """A car settled 12 m ahead in the left lane pulls out at 2 s, its lateral speed rising at 3 m/s^2 to 1.8 m/s:
    (the frame it is first flagged on, the frame its centre crosses the boundary, each frame's (lateral speed
    towards the ego lane, its 1-sigma) [m/s])."""
    slot = NeighbourSlot(StereoRig(), None, DT)
    lat, speed, lats = W, 0.0, [W] * 30
    while lat > W / 2 - 0.5:
        speed = min(speed + 3.0 * DT, 1.8)
        lat -= speed * DT
        lats.append(lat)
    slot.front = _FakeFinder([det(12.0, y) for y in lats])
    flagged = crossed = None
    speeds = []
    for k, y in enumerate(lats):
        nb, _ = slot.step(FRONT_ONLY, {EgoPath: EgoPath.straight(25.0)})
        (t,) = slot.tracker.tracks
        speeds.append((-float(t.kf.x[3, 0]), float(np.sqrt(t.kf.P[3, 3]))))
        if flagged is None and nb.cutting_in() is not None:
            flagged = k
        if crossed is None and y <= W / 2:
            crossed = k
    return flagged, crossed, speeds


def test_a_car_pulling_out_close_ahead_is_flagged_while_its_speed_is_within_two_sigma():
    flagged, crossed, speeds = _pull_out()
    assert flagged is not None and flagged < crossed
    toward, sigma = speeds[flagged]
    # flagged on the manoeuvre: its lateral speed not yet beyond speed_sigmas of its estimate
    assert NeighbourConfig().min_lateral_speed_mps < toward < NeighbourConfig().speed_sigmas * sigma


def test_a_car_whose_face_jitters_across_its_lane_is_never_flagged():
    slot = NeighbourSlot(StereoRig(), None, DT)
    rng = np.random.default_rng(0)
    # a minute 12 m ahead in the left lane, its face's lateral place off by 0.12 m (1-sigma) on each frame
    slot.front = _FakeFinder([det(12.0, W + e) for e in rng.normal(0.0, 0.12, int(60 / DT))])
    for _ in range(int(60 / DT)):
        nb, _ = slot.step(FRONT_ONLY, {EgoPath: EgoPath.straight(25.0)})
        assert nb.cutting_in() is None


def _far_veer(sigma_lat_m: float) -> bool:
    """Whether a car 69 m ahead in the left lane is flagged when its filter reads it 0.40 m off its lane's centre
    towards the ego lane at 0.66 m/s (1-sigma 0.40 m/s), after three lateral innovations that way in a row, with its
    lateral place known to ``sigma_lat_m`` [m]."""
    slot = NeighbourSlot(StereoRig(), None, DT)
    slot.front = _FakeFinder([det(69.0, W) for _ in range(30)])
    for _ in range(30):
        slot.step(FRONT_ONLY, {EgoPath: EgoPath.straight(25.0)})
    (t,) = slot.tracker.tracks
    t.kf.x[2, 0], t.kf.x[3, 0], t.kf.P[2, 2] = W - 0.40, -0.66, sigma_lat_m**2
    t.veer = -slot.tracker.cfg.manoeuvre_frames - 1
    assert slot.tracker.manoeuvring(t)
    cut_in, _ = slot._intent(t, t.lat, -0.66, 1, W, sigma_lat_m, 0.40, 25.0)
    return cut_in


def test_a_far_manoeuvre_counts_only_once_the_car_has_left_its_lane_centre_beyond_its_place_uncertainty():
    # 0.40 m is within three sigma of a place known to 0.15 m (a far face in rain), beyond three of one known to 0.10 m
    assert not _far_veer(0.15)
    assert _far_veer(0.10)
