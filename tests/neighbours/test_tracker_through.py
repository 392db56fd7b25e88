"""Cut-in warnings for a car coming over from the lane beyond: one that settles in the lane beside is no cut-in (it
has not been a settled neighbour there), one that goes straight on into the ego lane is (``through_shift_m``); and
for a person crossing, who is none (``min_ground_speed_mps``)."""

from percept.neighbours import NeighbourConfig, NeighbourSlot, TrackerConfig
from percept.sensors import EgoPath, StereoRig

from .test_tracker import DT, FRONT_ONLY, W, _FakeFinder, det


def test_a_car_coming_over_from_the_lane_beyond_is_not_cutting_in():
    slot = NeighbourSlot(StereoRig(), None, DT)
    # 30 m ahead two lanes to the left, moving right at 1 m/s into the next lane and half a metre past its centre (a
    # ramp's car arriving in the acceleration lane), then keeping there
    lat = [1.6 * W - 1.0 * k * DT for k in range(int((0.6 * W + 0.5) / DT))]
    lat += [lat[-1]] * 45
    slot.front = _FakeFinder([det(32.0, y) for y in lat])
    for _ in lat:
        nb, _ = slot.step(FRONT_ONLY, {EgoPath: EgoPath.straight(25.0)})
        assert nb.cutting_in() is None
    # it is a settled neighbour in its lane once it has kept still there
    (track,) = slot.tracker.tracks
    assert track.lane == 1 and track.settled >= TrackerConfig().min_settled


def test_a_car_coming_over_from_the_lane_beyond_and_on_into_the_ego_lane_is_flagged_before_it_crosses():
    slot = NeighbourSlot(StereoRig(), None, DT)
    # 30 m ahead two lanes to the left, moving right at 1 m/s without a pause (a ramp's car merging straight on)
    lat = [1.6 * W - 1.0 * k * DT for k in range(int(1.6 * W / DT))]
    slot.front = _FakeFinder([det(32.0, y) for y in lat])
    flagged_at = crossed_at = None
    for k, y in enumerate(lat):
        nb, _ = slot.step(FRONT_ONLY, {EgoPath: EgoPath.straight(25.0)})
        if nb.cutting_in() is not None and flagged_at is None:
            flagged_at = k
        if y <= W / 2 and crossed_at is None:
            crossed_at = k
    assert slot.tracker.tracks[0].settled == 0  # never a settled neighbour
    # flagged once 0.7 m past its lane's centre: 1.3 m, at 1 m/s, before the boundary
    assert flagged_at is not None and (crossed_at - flagged_at) * DT >= 1.0


def _crossing(cfg: NeighbourConfig) -> bool:
    """Whether a person crossing is ever flagged: standing at the kerb in the lane beside, 90 m ahead, then walking
    across at 1.4 m/s while the ego comes on at 25 m/s (still on the ground: a track closing at the ego's speed)."""
    slot = NeighbourSlot(StereoRig(), None, DT, cfg)
    lat = [W] * 25 + [W - 1.4 * k * DT for k in range(1, 30)]
    slot.front = _FakeFinder([det(90.0 - 25.0 * k * DT, y) for k, y in enumerate(lat)])
    flagged = False
    for _ in lat:
        nb, _ = slot.step(FRONT_ONLY, {EgoPath: EgoPath.straight(25.0)})
        flagged = flagged or nb.cutting_in() is not None
    return flagged


def test_a_person_crossing_the_road_is_not_a_cut_in():
    assert not _crossing(NeighbourConfig())
    # only the speed over the ground rules it out
    assert _crossing(NeighbourConfig(min_ground_speed_mps=0.0))
