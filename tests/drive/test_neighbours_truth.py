"""The true neighbours: lanes either side, zones and bumper gaps, relative and lateral speeds, the rig that sees each
vehicle, the cut-in flag, and the privileged slot that reports them."""

import math
from dataclasses import replace
from types import SimpleNamespace

import pytest

from percept.drive.neighbours_truth import PrivilegedNeighbours, cut_in, truth_neighbours
from percept.drive.privileged import TruthFeed
from percept.sensors import ObjectKind, Zone


def by_id(neighbours):
    return {n.track_id: n for n in neighbours.tracks}


def test_lanes_either_side_from_the_lateral_position_against_the_ego_lane(vehicle, truth):
    cars = [vehicle(1, 30, 4.0), vehicle(2, 30, -3.5), vehicle(3, 30, 1.9), vehicle(4, 30, 8.5), vehicle(5, 30, -6.1)]
    n = by_id(truth_neighbours(truth(cars)))
    assert (n[1].lane, n[2].lane, n[3].lane) == (1, -1, 0)
    assert n[1].lateral_m == pytest.approx(0.0) and n[2].lateral_m == pytest.approx(0.5)
    assert n[3].lateral_m == pytest.approx(1.9)
    assert 4 not in n and 5 not in n   # two lanes away


def test_lanes_follow_the_ego_offset_and_the_curve(vehicle, truth):
    # the ego 1 m left of its lane's centre: the centre is at y = -1, so y = +1.2 is 2.2 m left of it (lane +1)
    n = by_id(truth_neighbours(truth([vehicle(1, 10, 1.2)], offset=1.0)))
    assert n[1].lane == 1 and n[1].lateral_m == pytest.approx(2.2 - 4.0)
    # a left curve of 500 m radius: 40 m ahead its centre is 1.6 m left
    n = by_id(truth_neighbours(truth([vehicle(1, 40, 5.6), vehicle(2, 40, 1.6)], curvature=1 / 500)))
    assert (n[1].lane, n[2].lane) == (1, 0) and n[1].lateral_m == pytest.approx(0.0)


def test_zones_and_bumper_gaps_and_the_ranges_covered(vehicle, truth):
    cars = [vehicle(1, 20, 0), vehicle(2, -20, 4.0, rear_visible=1.0, visible=0), vehicle(3, 4.0, -4.0),
            vehicle(4, 90, 0), vehicle(5, -95, 0), vehicle(6, 50, 0, length=12.0)]
    n = by_id(truth_neighbours(truth(cars)))
    assert (n[1].zone, n[1].gap_m) == (Zone.AHEAD, pytest.approx(15.0))
    assert (n[2].zone, n[2].gap_m) == (Zone.BEHIND, pytest.approx(15.0))
    assert (n[3].zone, n[3].gap_m) == (Zone.BESIDE, 0.0)
    assert n[6].gap_m == pytest.approx(50 - 6 - 2.5) and n[6].length_m == 12.0
    assert 4 not in n and 5 not in n   # beyond 80 m ahead and 85 m behind
    wide = by_id(truth_neighbours(truth(cars), ahead_m=100, behind_m=100))
    assert 4 in wide and 5 in wide


def test_nearest_first_within_each_lane(vehicle, truth):
    cars = [vehicle(1, 60, 0), vehicle(2, -10, 0, visible=0), vehicle(3, 30, 4), vehicle(4, 12, 0)]
    assert [n.track_id for n in truth_neighbours(truth(cars)).tracks] == [2, 4, 1, 3]


def test_relative_speed_along_the_lane_and_lateral_speed(vehicle, truth):
    n = by_id(truth_neighbours(truth([vehicle(1, 30, 4.0, speed=30.0, lateral_speed=0.5)])))
    assert n[1].rel_speed_mps == pytest.approx(math.sqrt(30 ** 2 - 0.25) - 25.0)
    assert n[1].lateral_speed_mps == pytest.approx(0.5)
    # the ego heading 0.1 rad left of its lane: a car driving along the lane has yaw -0.1 relative to the ego
    # and the lane's centre 30 tan(0.1) m right of the ego's axis 30 m ahead
    y = 4.0 - 30 * math.tan(0.1)
    n = by_id(truth_neighbours(truth([vehicle(1, 30, y, speed=30.0, yaw=-0.1)], heading=0.1)))
    assert n[1].lane == 1 and n[1].lateral_m == pytest.approx(0.0)
    assert n[1].rel_speed_mps == pytest.approx(30.0 - 25.0 * math.cos(0.1))
    assert n[1].lateral_speed_mps == pytest.approx(0.0, abs=1e-9)


def test_the_rig_that_sees_a_vehicle_and_its_box(vehicle, truth):
    cars = [vehicle(1, 30, 0, visible=0.8), vehicle(2, -30, 0, visible=0, rear_visible=0.6),
            vehicle(3, 40, 4, visible=0.4), vehicle(4, 0, 4, visible=0)]
    n = by_id(truth_neighbours(truth(cars)))
    assert (n[1].camera, n[1].box_px) == ("front", cars[0].box_px)
    assert (n[2].camera, n[2].box_px) == ("rear", cars[1].rear_box_px)
    assert n[3].camera is None and n[3].box_px is None and n[3].predicted
    assert n[4].camera is None and n[1].sigma_x_m == n[1].sigma_rel_speed_mps == n[1].sigma_lateral_m == 0.0


def test_a_neighbour_moving_over_is_flagged_with_its_time_to_cross(vehicle, truth):
    # lane +1, 0.2 m right of its centre, moving right at 1 m/s: 1.8 m to the boundary, 1.8 s
    n = by_id(truth_neighbours(truth([vehicle(1, 30, 3.8, lateral_speed=-1.0), vehicle(2, 30, -3.8,
                                                                                          lateral_speed=1.0)])))
    assert n[1].cut_in and n[1].time_to_cross_s == pytest.approx(1.8)
    assert n[2].cut_in and n[2].time_to_cross_s == pytest.approx(1.8)
    # too slow to reach the boundary within 3 s; moving away; settling into its lane from the far side
    assert cut_in(1, -0.2, -0.5, 4.0) == (False, None)
    assert cut_in(1, -0.2, 1.0, 4.0) == (False, None)
    assert cut_in(1, 0.5, -1.0, 4.0) == (False, None)
    assert cut_in(0, 0.5, -1.0, 4.0) == (False, None)
    assert cut_in(-1, 0.0, 2.0, 4.0, horizon_s=0.5) == (False, None)


def test_only_vehicles_count_and_bad_ranges_are_refused(vehicle, truth):
    person = replace(vehicle(1, 20, 0), kind=ObjectKind.PEDESTRIAN)
    assert truth_neighbours(truth([person])).tracks == ()
    with pytest.raises(ValueError, match="ahead_m must be a finite number > 0"):
        truth_neighbours(truth(), ahead_m=0.0)
    with pytest.raises(ValueError, match="horizon_s must be a finite number > 0"):
        truth_neighbours(truth(), horizon_s=math.inf)


def test_the_privileged_slot_reports_the_truth_of_its_feed(vehicle, truth):
    feed = TruthFeed()
    slot = PrivilegedNeighbours(SimpleNamespace(truth=feed))
    slot.reset()
    feed.truth = truth([vehicle(7, 30, 4.0)])
    est, debug = slot.step(None, {})
    assert debug is None and [n.track_id for n in est.tracks] == [7]
    assert (est.ahead_m, est.behind_m, est.rear) == (80.0, 85.0, True)
