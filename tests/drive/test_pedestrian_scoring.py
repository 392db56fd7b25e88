"""The pedestrian scorer's stops and brakings, on hand-made truths: what calls for a stop and what does not."""

from types import SimpleNamespace

import numpy as np

from percept.drive.privileged import Obstacle
from percept.drive.scoring import PedestrianScorer, ScoreContext, StepTruth
from percept.sensors import BrakingRequest, ObjectKind


def drive(scorer, speeds, accels, obstacle=None, request=None, objects=()):
    for k, (v, a) in enumerate(zip(speeds, accels)):
        gt = SimpleNamespace(time_s=k / 15, speed_mps=v, objects=objects)
        scorer.update(request, None, StepTruth(gt, [], obstacle, a, 0.0))
    return scorer.result()


BRAKE_TO_A_STOP = (np.linspace(20.0, 0.0, 40), [-8.0] * 40)
GHOST = BrakingRequest(12.0, -20.0, "pedestrian in the path", ObjectKind.PEDESTRIAN, obj_id=4)


def scorer(pedestrians: int = 0) -> PedestrianScorer:
    return PedestrianScorer(ScoreContext(False, pedestrians, 0, 1.8))


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
