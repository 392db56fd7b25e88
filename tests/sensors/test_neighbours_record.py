"""The neighbours records: zones and gaps, a lane never free while a track may be in it, the cut-in lead."""

import pytest

from percept.sensors import Neighbour, Neighbours, Zone, zone_and_gap


def track(tid: int, lane: int, x: float, sigma: float = 0.2, cut_in: bool = False) -> Neighbour:
    zone, gap = zone_and_gap(x, 5.0)
    return Neighbour(tid, lane, zone, x, gap, -1.0, 0.0, 0.0, sigma_x_m=sigma, cut_in=cut_in,
                     time_to_cross_s=1.5 if cut_in else None)


def test_zones_and_bumper_gaps():
    assert zone_and_gap(25.0, 5.0) == (Zone.AHEAD, pytest.approx(20.0))
    assert zone_and_gap(-12.0, 5.0) == (Zone.BEHIND, pytest.approx(7.0))
    assert zone_and_gap(4.9, 5.0) == (Zone.BESIDE, 0.0)
    assert zone_and_gap(-4.9, 5.0) == (Zone.BESIDE, 0.0)


def test_a_lane_is_not_free_while_a_track_may_be_in_the_span():
    nb = Neighbours((track(1, 1, -20.0, sigma=0.2), track(2, -1, 0.0, sigma=6.0)))
    assert nb.lane_free(1, 15.0, 30.0)  # the left lane's car is 20 m back, beyond 15 m by more than 3 sigma
    assert not nb.lane_free(1, 19.5, 30.0)  # within 3 sigma of the span's end
    # a car held in the blind band with a wide uncertainty blocks far beyond its place
    assert not nb.lane_free(-1, 0.0, 15.0)
    assert nb.lane_free(-1, 0.0, 20.0) is False and nb.lane_free(0, 50.0, 50.0)


def test_the_nearest_car_cutting_in_ahead_is_the_lead():
    nb = Neighbours((track(1, 1, 40.0, cut_in=True), track(2, -1, 25.0, cut_in=True), track(3, 0, 15.0),
                     track(4, 1, 2.0, cut_in=True)))
    # the ego lane's car not flagged, and the car beside, are not cut-ins ahead
    assert nb.cutting_in().track_id == 2
    # one flagged on its way in stays the cut-in once in the ego lane
    assert Neighbours(nb.tracks + (track(5, 0, 12.0, cut_in=True),)).cutting_in().track_id == 5
    assert Neighbours((track(1, 1, 40.0),)).cutting_in() is None
