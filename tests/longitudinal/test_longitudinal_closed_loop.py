"""The vision longitudinal slot in closed loop (other slots privileged), scored against the simulator's truth,
and its degraded modes (dropped and black frames)."""

import numpy as np
import pytest

from percept.drive import DriveConfig, run_drive
from percept.longitudinal.slot import LongitudinalSlot
from percept.sensors import EgoPath, Frame, ImuSample, StereoRig
from percept.sims import WorldConfig


@pytest.mark.slow
def test_vision_longitudinal_follows_and_brakes_for_the_lead_without_collision():
    # lead-brake seed 1: the lead brakes at -6 m/s^2 to a stop; the full sweep (seeds 0-9 x clear, night, rain,
    # noise on highway, lead-brake and cut-in) is in the README; the car keeps its lane behind the lead
    r = run_drive(DriveConfig(WorldConfig("lead-brake", 1, scenery=False), sources={"longitudinal": "vision"},
                              default="privileged", lane_changes=False))
    assert r["collisions"] == 0 and r["lane_departures"] == 0
    lon = r["longitudinal"]
    assert lon["range_abs_rel_err"] < 0.03
    assert lon["time_gap_min_s"] > 1.0
    assert lon["time_gap_steady_s"] == pytest.approx(lon["time_gap_setting_s"], abs=0.3)
    assert r["timing_ms"]["longitudinal"] > 0 and lon["ttc_abs_err_s"] is not None


def frame(left, right, i=0, speed=20.0):
    return Frame(i, i / 15, left, right, ImuSample(np.zeros(3), np.zeros(3)), speed)


def test_dropped_and_featureless_frames_give_no_lead_and_no_error():
    slot = LongitudinalSlot(StereoRig(), 1 / 15)
    path = {EgoPath: EgoPath.straight(20.0)}
    lead, dbg = slot.step(frame(None, None), path)
    assert lead is None and dbg.obstacle is None and dbg.measured_m is None
    black = np.zeros((480, 640, 3), np.uint8)
    for i in range(5):
        lead, dbg = slot.step(frame(black, black, i), path)
        assert lead is None and dbg.obstacle is None
    # no ego path from upstream (e.g. a lateral slot that is not there): a straight corridor, at the last plausible
    # wheel speed when this frame's sample is bad
    for bad in (float("nan"), -30.0, None):
        lead, _ = slot.step(frame(black, black, speed=bad), {})
        assert lead is None and slot.motion.last.speed_mps == 20.0 and not slot.motion.last.speed_ok


def test_stereo_contact_and_flow_all_reach_the_filter():
    from percept.sims import SimWorld

    w = SimWorld(WorldConfig("lead-brake", 1, scenery=False))
    slot = LongitudinalSlot(w.cfg.rig, w.dt)
    used, errors = set(), []
    for _ in range(30):
        frame, gt = w.observe()
        lead, dbg = slot.step(frame, {EgoPath: EgoPath.straight(frame.wheel_speed_mps)})
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
        assert slot.update(61.0, None, ob, None) == () and slot.track is None
    refined = Refined(slot.fb / 12.0, 0.02, 200, True)
    car = Obstacle(12.0, (290, 220, 350, 290), 2000.0)
    for _ in range(slot.cfg.confirm):
        slot.predict()
        assert slot.update(12.0, refined, car, None) == ("stereo",)
    # confirmed at 12 m: the far match's noise is taken at the track's range, so it is no measurement of it ...
    slot.predict()
    assert slot.update(61.0, None, ob, None) == () and slot.track.range_m == pytest.approx(12.0, abs=0.2)
    # ... while a coarse range near the track still updates it (a lead whose face did not refine this frame)
    slot.predict()
    assert slot.update(12.3, None, car, None) == ("stereo",)


class _Scripted:
    """Stand-ins for the slot's cues: each frame's obstacle and whether its range refines, from a script."""

    def __init__(self, slot, script):
        self.script, self.fb = iter(script), slot.fb
        slot.finder.find = self.find
        slot.refine = lambda left, right, ob: self.refined
        slot.contact.measure = lambda gray, box, z: None
        slot.flow.measure = lambda gray, box, t: None

    def find(self, left, right, path):
        from percept.longitudinal import Obstacle, Refined

        range_m, refines = next(self.script)
        self.refined = Refined(self.fb / range_m, 0.02, 200, True) if refines else None
        return Obstacle(range_m, (300, 240, 340, 260), 800.0), {}


def run_script(script, speed_mps=10.0):
    slot = LongitudinalSlot(StereoRig(), 1 / 15)
    _Scripted(slot, script)
    grey = np.full((480, 640, 3), 128, np.uint8)
    out = []
    for i in range(len(script)):
        f = Frame(i, i / 15, grey, grey, ImuSample(np.zeros(3), np.zeros(3)), speed_mps)
        out.append(slot.step(f, {EgoPath: EgoPath.straight(speed_mps)}))
    return slot, out


def test_a_track_whose_range_stops_refining_is_dropped_after_hold_s():
    # a lead seen well, then a far box at the road's end that never refines: its coarse ranges agree with the
    # track (their noise at 60 m is metres) but do not keep it alive past hold_s
    slot, out = run_script([(60.0, True)] * 10 + [(60.0, False)] * 20)
    assert out[9][0] is not None
    hold = int(slot.cfg.hold_s * 15)
    assert out[9 + hold][0] is not None and out[9 + hold][0].confidence < 0.2
    assert all(lead is None for lead, _ in out[11 + hold:])
    assert slot.track is None
    # while a refined range now and then keeps it
    slot, out = run_script([(60.0, True), (60.0, False), (60.0, False)] * 10)
    assert all(lead is not None for lead, _ in out[6:])  # confirmed by its third refined range


def test_no_lead_comes_towards_the_ego_faster_than_the_ego_drives():
    # refined ranges alternating between 48 and 68 m on the same box: without the bound the filter takes them for a
    # lead braking hard and its rate reaches -93 m/s on a car doing 10
    slot, out = run_script([(68.0 if i % 4 < 2 else 48.0, True) for i in range(60)], speed_mps=10.0)
    rates = [dbg.state[1] for _, dbg in out if dbg.state is not None]
    assert min(rates) >= -(10.0 + slot.cfg.reverse_mps) - 1e-9
    assert min(rates) < -5.0  # the case is hard: it did pull the rate down to the bound
    # a car standing still ahead is closed on at the ego's speed, as it should be: the bound does not hide it
    slot, out = run_script([(60.0 - 10.0 * i / 15, True) for i in range(45)], speed_mps=10.0)
    assert out[-1][0].range_rate_mps == pytest.approx(-10.0, abs=0.5)
