"""The vision longitudinal slot in closed loop (other slots privileged), scored against the simulator's truth,
and its degraded modes (dropped and black frames)."""

import numpy as np
import pytest

from percept.drive import DriveConfig, run_drive
from percept.longitudinal.slot import LongitudinalSlot
from percept.sensors import EgoPath, Frame, ImuSample, StereoRig
from percept.sims import WorldConfig


def test_vision_longitudinal_follows_and_brakes_for_the_lead_without_collision():
    # lead-brake seed 1: the lead brakes at -6 m/s^2 to a stop; the full sweep (seeds 0-9 x clear, night, rain,
    # noise on highway, lead-brake and cut-in) is in the README
    r = run_drive(DriveConfig(WorldConfig("lead-brake", 1, scenery=False), sources={"longitudinal": "vision"}))
    assert r["collisions"] == 0 and r["lane_departures"] == 0
    lon = r["longitudinal"]
    assert lon["range_abs_rel_err"] < 0.03
    assert lon["time_gap_min_s"] > 1.0
    assert lon["time_gap_steady_s"] == pytest.approx(lon["time_gap_setting_s"], abs=0.3)
    assert r["timing_ms"]["longitudinal"] > 0 and lon["ttc_abs_err_s"] is not None


def frame(left, right, i=0):
    return Frame(i, i / 15, left, right, ImuSample(np.zeros(3), np.zeros(3)), 20.0)


def test_dropped_and_featureless_frames_give_no_lead_and_no_error():
    slot = LongitudinalSlot(StereoRig(), 1 / 15)
    path = {"lateral": EgoPath.straight(20.0)}
    lead, dbg = slot.step(frame(None, None), path)
    assert lead is None and dbg.obstacle is None and dbg.measured_m is None
    black = np.zeros((480, 640, 3), np.uint8)
    for i in range(5):
        lead, dbg = slot.step(frame(black, black, i), path)
        assert lead is None and dbg.obstacle is None
    # no ego path from upstream (e.g. a lateral slot that is not there): a straight corridor
    lead, _ = slot.step(frame(black, black), {})
    assert lead is None


def test_stereo_contact_and_flow_all_reach_the_filter():
    from percept.sims import SimWorld

    w = SimWorld(WorldConfig("lead-brake", 1, scenery=False))
    slot = LongitudinalSlot(w.cfg.rig, w.dt)
    used, errors = set(), []
    for _ in range(30):
        frame, gt = w.observe()
        lead, dbg = slot.step(frame, {"lateral": EgoPath.straight(frame.wheel_speed_mps)})
        used.update(dbg.used)
        true = min((o.distance_m for o in gt.objects if o.kind.value == "vehicle" and abs(o.position_m[1]) < 1.5))
        if dbg.contact is not None:
            errors.append(abs(dbg.contact.range_m - true) / true)
        w.step(0.0, 0.0)
    assert used == {"stereo", "contact", "flow"}
    assert lead is not None and abs(lead.range_m - true) / true < 0.01
    # ground contact alone, at about 45 m: a few per cent (a row is 2.6 m there)
    assert np.median(errors) < 0.04


def test_a_range_that_does_not_refine_neither_starts_a_track_nor_drags_one_away():
    from percept.longitudinal import Obstacle, Refined

    slot = LongitudinalSlot(StereoRig(), 1 / 15)
    ob = Obstacle(61.0, (309, 239, 316, 250), 28.0)
    # chance matches on the dark background at the road's far end: a coarse range without a refined disparity
    for _ in range(5):
        assert slot._update(61.0, None, ob, None) == () and slot.kf is None
    refined = Refined(slot.fb / 12.0, 0.02, 200, True)
    car = Obstacle(12.0, (290, 220, 350, 290), 2000.0)
    for _ in range(slot.cfg.confirm):
        slot._predict()
        assert slot._update(12.0, refined, car, None) == ("stereo",)
    # confirmed at 12 m: the far match's noise is taken at the track's range, so it is no measurement of it ...
    slot._predict()
    assert slot._update(61.0, None, ob, None) == () and slot.kf.x[0, 0] == pytest.approx(12.0, abs=0.2)
    # ... while a coarse range near the track still updates it (a lead whose face did not refine this frame)
    slot._predict()
    assert slot._update(12.3, None, car, None) == ("stereo",)
