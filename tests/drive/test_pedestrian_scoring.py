"""The pedestrian scorer's stops and brakings, on hand-made truths: what calls for a stop and what does not."""

from types import SimpleNamespace

import numpy as np

from percept.drive.privileged import Obstacle
from percept.drive.pedestrian_scoring import PedestrianScorer, person_matches
from percept.drive.scoring import ScoreContext, StepTruth
from percept.sensors import BrakingRequest, ObjectKind, StereoRig


def drive(scorer, speeds, accels, obstacle=None, request=None, objects=()):
    for k, (v, a) in enumerate(zip(speeds, accels)):
        gt = SimpleNamespace(time_s=k / 15, speed_mps=v, objects=objects)
        scorer.update(request, None, StepTruth(gt, [], obstacle, a, 0.0))
    return scorer.result()


BRAKE_TO_A_STOP = (np.linspace(20.0, 0.0, 40), [-8.0] * 40)
GHOST = BrakingRequest(12.0, -20.0, "pedestrian in the path", ObjectKind.PEDESTRIAN, obj_id=4)


def scorer(pedestrians: int = 0, fb: float | None = None) -> PedestrianScorer:
    return PedestrianScorer(ScoreContext(False, pedestrians, 0, 1.8, fb))


RIG = StereoRig()
FB = RIG.camera.fx * RIG.baseline_m
"""The default rig's focal length times baseline [px m] (299.3): one disparity pixel is 5.9 m of range at 42 m."""


def test_a_stop_behind_a_lead_that_drives_on_is_false_even_without_pedestrians():
    lead = Obstacle(49.0, 19.9, ObjectKind.VEHICLE)
    r = drive(scorer(), *BRAKE_TO_A_STOP, obstacle=lead, request=GHOST)
    # a road with nobody on it: the stop and the hard braking for a person were both for no one
    assert r["false_stops"] == 1 and r["brakes_for_no_one"] == 1
    assert r["verge_brakes"] is None and r["stops"] is None   # no pedestrians: nobody on a verge, nobody to stop for


def test_a_stop_behind_a_halted_vehicle_is_not_false():
    halted = Obstacle(6.0, 0.0, ObjectKind.VEHICLE)
    r = drive(scorer(), *BRAKE_TO_A_STOP, obstacle=halted)
    assert r["false_stops"] == 0 and r["brakes_for_no_one"] == 0


def test_a_braking_for_a_person_on_the_verge_is_a_verge_brake_not_one_for_no_one():
    person = SimpleNamespace(obj_id=4, kind=ObjectKind.PEDESTRIAN, crossing=False, position_m=np.array([60.0, 5.0, 0]))
    r = drive(scorer(1), *BRAKE_TO_A_STOP, request=GHOST, objects=(person,))
    assert r["verge_brakes"] == 1 and r["brakes_for_no_one"] == 0 and r["false_stops"] == 1


def track_request(x: float, y: float):
    """A vision track's braking request and the slot's debug holding that track at (x, y)."""
    debug = SimpleNamespace(tracks=[SimpleNamespace(track_id=4, position_m=(x, y))])
    return GHOST, debug


def drive_track(scorer, track_xy, person):
    request, debug = track_request(*track_xy)
    speeds, accels = BRAKE_TO_A_STOP
    for k, (v, a) in enumerate(zip(speeds, accels)):
        gt = SimpleNamespace(time_s=k / 15, speed_mps=v, objects=(person,))
        scorer.update(request, debug, StepTruth(gt, [], None, a, 0.0))
    return scorer.result()


def crossing_person(x: float, y: float):
    return SimpleNamespace(obj_id=9, kind=ObjectKind.PEDESTRIAN, crossing=True, position_m=np.array([x, y, 0.0]))


def test_a_person_stereo_read_a_pixel_short_is_still_the_person_braked_for():
    # a crossing person at 42 m, tracked 4.1 m short (less than the 5.9 m one disparity pixel spans there)
    r = drive_track(scorer(1, FB), (37.9, 0.2), crossing_person(42.0, 0.0))
    assert r["brakes_for_no_one"] == 0 and r["verge_brakes"] == 0
    # without the rig's resolution only the 3 m on the ground count (the rule before)
    r = drive_track(scorer(1), (37.9, 0.2), crossing_person(42.0, 0.0))
    assert r["brakes_for_no_one"] == 1


def test_a_track_beside_a_person_or_far_short_of_a_near_one_is_for_no_one():
    # 4 m to the side at 42 m: range resolution does not widen the lateral match
    assert drive_track(scorer(1, FB), (42.0, 4.0), crossing_person(42.0, 0.0))["brakes_for_no_one"] == 1
    # 5 m short of a person at 15 m: a disparity pixel is 0.33 m of range at the track's 10 m
    assert drive_track(scorer(1, FB), (10.0, 0.0), crossing_person(15.0, 0.0))["brakes_for_no_one"] == 1


def test_person_matches_widens_only_along_the_range_by_one_disparity_pixel():
    assert person_matches((20.0, 0.0), (22.9, 0.0), None)            # within 3 m on the ground
    assert not person_matches((20.0, 0.0), (23.5, 0.0), None)
    # at 20 m one pixel is 20^2 / 299.3 = 1.34 m: 3 + 1.34 along x
    assert person_matches((20.0, 0.0), (24.2, 0.0), FB)
    assert not person_matches((20.0, 0.0), (24.5, 0.0), FB)
    assert not person_matches((20.0, 0.0), (21.0, 3.1), FB)
    assert not person_matches((-5.0, 0.0), (-1.0, 0.0), FB)          # behind: no range to widen by
