"""Analytic checks of the evasion law on neighbours records: when braking alone falls short, which lane it swerves
into, and full braking where no lane is free; the lane-change law flying the swerve."""

import pytest

from percept.control import Evasion, EvasionConfig, LaneChange, Phase, Target, nearest_target
from percept.sensors import Neighbour, Neighbours, ObjectKind, zone_and_gap
from percept.sensors.vehicle import EGO_LENGTH_M, MAX_BRAKE_MPS2

from .test_lane_change import DT, V, around, car, path


def cutter(lane, x, rel, track_id=7):
    """A car in ``lane`` flagged as cutting into the ego lane."""
    zone, gap = zone_and_gap(x, EGO_LENGTH_M)
    return Neighbour(track_id, lane, zone, x, gap, rel, -lane * 1.0, -lane * 1.5, EGO_LENGTH_M, 0.2, 0.3, 0.1,
                     cut_in=True, time_to_cross_s=0.6)


def vehicle(gap, closing, source="cut-in"):
    return Target(gap, closing, ObjectKind.VEHICLE, source)


def test_braking_falls_short_when_the_emergency_laws_demand_passes_its_limit():
    law = Evasion(25.0, EvasionConfig(margin_m=1.0))
    # STOP_GAIN c^2 / (2 (g - margin)) = 1.3 * 100 / 20
    assert law.needed(vehicle(11.0, 10.0)) == pytest.approx(6.5)
    assert law.needed(vehicle(11.0, -2.0)) is None  # opening
    assert law.needed(Target(5.0, 10.0, ObjectKind.PEDESTRIAN, "request")) is None
    assert law.needed(vehicle(5.0, 10.0, "target lane")) is None
    # 1.3 c^2 / (2 (g - 1)) = MAX_BRAKE at the gap below
    edge = 1.0 + 1.3 * 14.0 ** 2 / (2 * MAX_BRAKE_MPS2)
    assert law.needed(vehicle(edge + 0.5, 14.0)) < MAX_BRAKE_MPS2 < law.needed(vehicle(edge - 0.5, 14.0))


def test_it_swerves_away_from_the_car_cutting_in_after_the_confirming_frames():
    cut = cutter(-1, 14.0, rel=-14.0)
    law = Evasion(25.0, EvasionConfig(confirm_frames=2))
    target = nearest_target(None, None, around(cut))
    assert target.source == "cut-in"
    first = law.update(target, path(), around(cut), V)
    second = law.update(target, path(), around(cut), V)
    assert first[0] == 0 and first[1].short_frames == 1
    assert second[0] == 1 and second[1].event == "swerve" and second[1].reason == "swerve left"
    # the manoeuvre is one event
    assert law.update(target, path(), around(cut), V)[1].event is None


def test_with_braking_enough_it_keeps_its_lane():
    cut = cutter(-1, 40.0, rel=-8.0)
    law = Evasion(25.0)
    for _ in range(5):
        side, dbg = law.update(nearest_target(None, None, around(cut)), path(), around(cut), V)
    assert side == 0 and dbg.reason == "braking suffices" and dbg.needed_mps2 < MAX_BRAKE_MPS2


@pytest.mark.parametrize("why", ["beside", "no lane", "no view behind"])
def test_with_no_free_lane_it_is_full_braking(why):
    cut = cutter(-1, 14.0, rel=-14.0)
    cars = (cut, car(1, 0.0, track_id=2)) if why == "beside" else (cut,)
    record = Neighbours(around(*cars).tracks, rear=why != "no view behind")
    lanes = path(beside=(False, True)) if why == "no lane" else path()
    law = Evasion(25.0, EvasionConfig(confirm_frames=1))
    side, dbg = law.update(nearest_target(None, None, record), lanes, record, V)
    assert side == 0 and dbg.event == "full braking" and dbg.reason == "no free lane: full braking"


def test_the_lane_change_law_flies_the_swerve_at_once_and_fast():
    cut = cutter(-1, 14.0, rel=-14.0)
    law = LaneChange(30.0)
    law.since_end_s = 0.0  # a change has just ended: a swerve does not wait for the interval
    target = nearest_target(None, None, around(cut))
    dbgs = [law.update(path(), around(cut), V, DT, target)[1] for _ in range(3)]
    assert [d.event for d in dbgs] == [None, "swerve", None]
    assert dbgs[1].phase is Phase.EVADE and dbgs[1].side == 1 and dbgs[1].into_lane == 1
    assert law.path.duration_s == EvasionConfig().duration_s
    # lane keeping may jerk the car as hard as the swerve asks
    assert all(d.ref.max_jerk_mps3 is None for d in dbgs[1:])


@pytest.mark.parametrize("opened", [True, False])
def test_no_swerve_into_a_lane_that_opened_beside_the_car_lately(opened):
    # a lead closing at 14 m/s 14 m ahead, no lane on the left; on the right a lane that has just opened (an
    # acceleration lane, whose end nothing marks: full braking) or one that was always there (a swerve into it)
    law = LaneChange(30.0)
    lead = vehicle(14.0, 14.0, "lead")
    law.update(path(beside=(False, not opened)), around(), V, DT)
    dbgs = [law.update(path(beside=(False, True)), around(), V, DT, lead)[1] for _ in range(3)]
    events = [d.event for d in dbgs]
    assert events == ([None, "full braking", None] if opened else [None, "swerve", None])
