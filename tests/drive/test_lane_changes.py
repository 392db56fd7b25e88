"""Lane changes scored against truth, and driven in closed loop on truth and on vision."""

import numpy as np
import pytest

from percept.control import Phase
from percept.drive import DriveConfig, run_drive
from percept.drive.lane_change_scoring import LaneChangeScorer, ProgressScorer
from percept.drive.scoring import SafetyScorer, StepTruth
from percept.sensors import ImuSample
from percept.sensors.vehicle import MAX_BRAKE_MPS2
from percept.sims import WorldConfig


class Changing:
    """The parts of a LaneChangeDebug the scorers read."""

    def __init__(self, phase=Phase.CHANGE, event=None):
        self.phase, self.event = phase, event


def _departures(truth, frames, side: int | None) -> int:
    """Lane departures over ``frames``, each (offset [m], true lane id), during a change to ``side`` (None: none)."""
    s = SafetyScorer()
    for offset, lane in frames:
        s.update(StepTruth(truth(offset=offset, lane_index=("a", "b", lane)), [], None, 0.0, 0.0, side))
    return s.result()["lane_departures"]


def test_a_boundary_crossed_in_a_commanded_change_is_no_departure(truth):
    # a 2 m car in a 4 m lane: a body edge is over a line beyond 1 m; lane 1 to lane 0 on the left, the centre
    # crossing between the third and fourth frames
    left = [(0.0, 1), (0.6, 1), (1.2, 1), (-1.6, 0), (-0.4, 0)]
    assert _departures(truth, left, side=None) == 1
    assert _departures(truth, left, side=+1) == 0
    assert _departures(truth, left, side=0) == 0  # highway-env's MOBIL in the ego's place: any boundary
    # the car drifts over the right boundary while a change to the left is commanded: a departure
    assert _departures(truth, [(0.0, 1), (-0.6, 1), (-1.2, 1)], side=+1) == 1
    # in the new lane, over its far (left) boundary: a departure too
    assert _departures(truth, left + [(0.6, 0), (1.2, 0)], side=+1) == 1


def test_the_laws_idm_is_highway_envs():
    from highway_env.vehicle.behavior import IDMVehicle
    from highway_env.vehicle.kinematics import Vehicle

    from percept.control import mobil

    assert (mobil.ACCEL_MPS2, mobil.DECEL_MPS2, mobil.TIME_GAP_S, mobil.DELTA) == (
        IDMVehicle.COMFORT_ACC_MAX, -IDMVehicle.COMFORT_ACC_MIN, IDMVehicle.TIME_WANTED, IDMVehicle.DELTA)
    # highway-env's desired distance is centre to centre, ours bumper to bumper
    assert mobil.JAM_GAP_M == IDMVehicle.DISTANCE_WANTED - Vehicle.LENGTH


@pytest.mark.parametrize("behind_m, speed, unsafe", [(12.0, 25.0, True), (65.0, 25.0, False), (95.0, 37.0, True)])
def test_a_change_onto_a_close_or_fast_follower_is_unsafe_onto_a_far_one_not(truth, vehicle, behind_m, speed, unsafe):
    s = LaneChangeScorer(1 / 15)
    s.update(truth(lane_index=("a", "b", 1)), Changing(event="started"))
    # the ego's centre now in lane 0 at 25 m/s, a car behind it there: at its speed, or beyond the rigs' view and
    # closing at 12 m/s
    s.update(truth([vehicle(5, -behind_m, 0.0, speed=speed)], lane_index=("a", "b", 0)), Changing())
    r = s.result()
    assert r["started"] == 1 and r["unsafe"] == int(unsafe)
    crossing = r["crossings"][0]
    assert crossing["gap_behind_m"] == pytest.approx(behind_m - 5.0) and crossing["unsafe"] is unsafe


def test_lateral_acceleration_and_jerk_are_taken_over_the_change_only(truth):
    dt = 0.1
    s = LaneChangeScorer(dt)
    for a, phase in ((3.0, Phase.KEEP), (0.5, Phase.CHANGE), (0.8, Phase.CHANGE), (0.2, Phase.KEEP)):
        gt = truth()
        gt = gt.__class__(**{**gt.__dict__, "imu": ImuSample(np.array([0.0, a, 9.81]), np.zeros(3))})
        s.update(gt, Changing(phase))
    r = s.result()
    # jerk: |0.8 - 0.5| / dt
    assert r["peak_lateral_accel_mps2"] == pytest.approx(0.8) and r["peak_lateral_jerk_mps3"] == pytest.approx(0.3 / dt)


def test_progress_is_the_mean_speed_over_the_set_one(truth):
    p = ProgressScorer(30.0, 0.5)
    assert p.result()["mean_speed_mps"] is None
    for v in (20.0, 25.0):
        p.update(truth(speed=v))
    assert p.result() == {"mean_speed_mps": 22.5, "set_speed_ratio": 0.75, "distance_m": 22.5}


@pytest.mark.slow
def test_on_truth_the_car_overtakes_in_dense_traffic_and_keeps_its_lane_when_told():
    on = run_drive(DriveConfig(WorldConfig("dense", 0), default="privileged", lane_changes=True), render=False)
    off = run_drive(DriveConfig(WorldConfig("dense", 0), default="privileged", lane_changes=False), render=False)
    lc = on["lane_changes"]
    assert lc["completed"] >= 1 and lc["unsafe"] == 0 and on["lane_changes_on"]
    assert on["collisions"] == 0 and on["lane_departures"] == 0
    assert lc["peak_lateral_accel_mps2"] <= 2.0 and lc["peak_lateral_jerk_mps3"] <= 3.0
    assert off["lane_changes"]["started"] is None and not off["lane_changes_on"]
    assert on["progress"]["mean_speed_mps"] > off["progress"]["mean_speed_mps"]


@pytest.mark.slow
def test_on_vision_the_lane_estimate_follows_the_car_into_the_next_lane():
    indices, sides = [], []

    class Look:
        def log_step(self, frame, truth, step):
            indices.append(step.estimates["lanes"].lane.index)
            change = step.control["lane_change"]
            sides.extend([change.side] if change.event == "started" else [])

    # dense: held up in the first seconds, with a gap beside
    r = run_drive(DriveConfig(WorldConfig("dense", 8), duration_s=12.0, lane_changes=True),
                  recorder_factory=lambda w: Look())
    assert r["lane_changes"]["completed"] == 1 and r["lane_changes"]["unsafe"] == 0
    assert r["collisions"] == 0 and r["lane_departures"] == 0
    assert len(sides) == 1 and indices[-1] - indices[0] == sides[0]  # one lane over, to the side it changed to


@pytest.mark.parametrize("seed", [0, 2])
def test_on_truth_only_a_swerve_avoids_the_close_cut_in(seed):
    cfg = WorldConfig("cut-in-close", seed)
    braking = run_drive(DriveConfig(cfg, default="privileged", duration_s=15.0, lane_changes=False), render=False)
    evading = run_drive(DriveConfig(cfg, default="privileged", duration_s=15.0, lane_changes=True), render=False)
    assert braking["collisions"] == 1 and braking["evasive"]["count"] is None
    ev = evading["evasive"]
    assert evading["collisions"] == 0 and evading["lane_departures"] == 0 and evading["unsafe_lane_changes"] == 0
    assert (ev["count"], ev["swerves"], ev["full_braking"], ev["collisions"]) == (1, 1, 0, 0)
    # swerves are left out of the change's comfort peaks
    assert evading["lane_changes"]["peak_lateral_accel_mps2"] is None


def test_on_truth_with_the_other_lane_taken_braking_avoids_the_milder_cut_in_and_nothing_swerves():
    accels = []

    class Look:
        def log_step(self, frame, truth, step):
            accels.append(step.accel_mps2)

    r = run_drive(DriveConfig(WorldConfig("cut-in-close", 1), default="privileged", duration_s=15.0,
                              lane_changes=True), recorder_factory=lambda w: Look(), render=False)
    assert r["collisions"] == 0 and r["evasive"]["swerves"] == 0 and r["unsafe_lane_changes"] == 0
    assert min(accels) == pytest.approx(-MAX_BRAKE_MPS2)  # full braking
