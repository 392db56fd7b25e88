"""The neighbours scorer on hand-made truths: recall per zone and lane, lane and gap errors, vehicles beside the ego
reported absent, cut-in warnings early, late and false, and who moved into whom in a collision."""

import json
from dataclasses import replace
from types import SimpleNamespace

import pytest

from percept.drive.neighbours_scoring import NeighbourScorer, match_tracks
from percept.drive.neighbours_truth import truth_neighbours
from percept.drive.privileged import TruthFeed
from percept.drive.scoring import ScoreContext, StepTruth
from percept.drive.tasks import lazy
from percept.sensors import Neighbour, Neighbours, Zone

DT = 0.1


def scorer(vision: bool = True) -> NeighbourScorer:
    return NeighbourScorer(ScoreContext(vision, 0, 0, 1.8))


def run(frames, vision: bool = True) -> dict:
    """Score ``frames``: (ground truth, estimated tracks) pairs."""
    s = scorer(vision)
    for gt, tracks in frames:
        s.update(Neighbours(tuple(tracks)), None, StepTruth(gt, [], None, 0.0, 0.0))
    return s.result()


def mirrored(gt, **changes):
    """The true neighbours of ``gt`` as tracks (ids + 100), with ``changes`` to every one."""
    return [replace(n, track_id=n.track_id + 100, **changes) for n in truth_neighbours(gt, 100, 100).tracks]


def test_nothing_to_score_is_none_never_zero(truth):
    r = run([(truth(time_s=k * DT), []) for k in range(20)])
    for key in ("recall_ahead", "recall_beside", "recall_behind", "lane_accuracy", "gap_abs_rel_err_ahead",
                "gap_abs_rel_err_behind", "rel_speed_abs_err_mps", "cut_in_warning_lead_s_min"):
        assert r[key] is None, key
    assert r["recall_ahead_by_lane"] == {"-1": None, "0": None, "1": None}
    assert r["gap_abs_rel_err_by_bin"]["behind"] == {"0-20": None, "20-40": None, "40-60": None, "60-80": None}
    assert (r["cut_ins"], r["cut_ins_missed"], r["beside_absent_frames"], r["frames"]) == (0, 0, 0, 20)
    assert r["false_warnings_per_min"] == 0.0 and r["collisions"] == []
    assert json.loads(json.dumps(r)) == r


def test_the_table_can_make_the_slot_and_the_scorer_by_name(vehicle, truth):
    feed = TruthFeed()
    slot = lazy("percept.drive.neighbours_truth:PrivilegedNeighbours")(SimpleNamespace(truth=feed, dt_s=DT))
    s = lazy("percept.drive.neighbours_scoring:NeighbourScorer")(ScoreContext(True, 0, 0, 1.8))
    feed.truth = truth([vehicle(1, 30.0, 0.0)])
    est, debug = slot.step(None, {})
    s.update(est, debug, StepTruth(feed.truth, [], None, 0.0, 0.0))
    r = s.result()
    assert r["recall_ahead"] == 1.0 and r["frames"] == 1 and json.loads(json.dumps(r)) == r


def test_recall_per_zone_and_lane_with_a_missed_vehicle(vehicle, truth):
    cars = [vehicle(1, 30, 0), vehicle(2, 40, 4), vehicle(3, -30, -4, visible=0, rear_visible=1.0),
            vehicle(4, -30, 0, visible=0), vehicle(5, 70, 0), vehicle(6, 40, -4, visible=0.3)]
    gt = truth(cars)
    seen = [t for t in mirrored(gt) if t.track_id in (101, 103, 105)]
    r = run([(gt, seen)])
    # ahead: 1 found, 2 missed (4 unseen by the rear rig, 5 beyond 60 m, 6 under half visible: not counted)
    assert r["recall_ahead"] == 0.5 and r["recall_ahead_by_lane"] == {"-1": None, "0": 1.0, "1": 0.0}
    assert r["recall_behind"] == 1.0 and r["recall_behind_by_lane"]["-1"] == 1.0
    assert r["recall_beside"] is None and r["counts"]["ahead"] == {"matched": 1, "eligible": 2}
    assert r["lane_accuracy"] == 1.0 and r["gap_abs_rel_err_ahead"] == 0.0 and r["rel_speed_abs_err_mps"] == 0.0


def test_lane_gap_and_speed_errors_over_matched_pairs(vehicle, truth):
    gt = truth([vehicle(1, 30, 0, speed=27.0), vehicle(2, 20, 2.5), vehicle(3, -20, -4, visible=0, rear_visible=1)])
    tracks = {t.track_id: t for t in mirrored(gt)}
    a, b, c = tracks[101], tracks[102], tracks[103]
    est = [replace(a, x_m=a.x_m + 0.5, gap_m=a.gap_m + 0.5, rel_speed_mps=a.rel_speed_mps + 0.3),
           replace(b, lane=0, lateral_m=2.4), replace(c, gap_m=c.gap_m * 1.04)]
    r = run([(gt, est)])
    assert r["lane_accuracy"] == pytest.approx(2 / 3)
    # ahead: 0.5 / 25 and 0 (gaps 25 m and 15 m); behind: 4 %
    assert r["gap_abs_rel_err_ahead"] == pytest.approx(0.01) and r["gap_abs_rel_err_behind"] == pytest.approx(0.04)
    assert r["gap_abs_rel_err_by_bin"]["ahead"] == {"0-20": 0.0, "20-40": pytest.approx(0.02), "40-60": None,
                                                    "60-80": None}
    assert r["rel_speed_abs_err_mps"] == pytest.approx(0.0)   # the median of 0.3, 0 and 0


def test_a_vehicle_beside_with_no_track_counts_its_frames(vehicle, truth):
    # seen ahead first (a rig saw it on its way beside the ego), then beside with no track for three frames
    seen = truth([vehicle(1, 20.0, 4.0, visible=1.0)], time_s=0.0)
    frames = [(seen, mirrored(seen))]
    for k in range(1, 6):
        gt = truth([vehicle(1, 0.0, 4.0, visible=0)], time_s=k * DT)
        frames.append((gt, [] if k < 4 else mirrored(gt, x_m=1.0)))
    r = run(frames)
    assert r["beside_absent_frames"] == 3
    assert r["recall_beside"] == pytest.approx(0.4) and r["recall_beside_by_lane"] == {"-1": None,
                                                                                        "1": pytest.approx(0.4)}


def test_a_vehicle_beside_since_the_start_and_never_seen_is_not_counted(vehicle, truth):
    frames = []
    for k in range(5):
        gt = truth([vehicle(1, 0.0, 4.0, visible=0)], time_s=k * DT)
        frames.append((gt, []))
    r = run(frames)
    assert r["beside_absent_frames"] == 0
    assert r["recall_beside"] is None


def cut_in_run(vehicle, truth, warned, seconds: float = 5.0, cross: bool = True):
    """Vehicle 1 30 m ahead in lane +1 moving right at 0.8 m/s (its centre crosses the boundary between 2.5 and 2.6 s;
    with ``cross`` False it keeps its lane); its track warns while ``warned(t)``."""
    frames = []
    for k in range(int(round(seconds / DT)) + 1):
        t = k / 10
        car = vehicle(1, 30.0, 4.04 - 0.8 * t, lateral_speed=-0.8) if cross else vehicle(1, 30.0, 4.0)
        gt = truth([car], time_s=t)
        frames.append((gt, mirrored(gt, cut_in=warned(t))))
    return frames


def test_a_cut_in_warned_1_5_s_before_it_crosses_scores_a_1_5_s_lead(vehicle, truth):
    r = run(cut_in_run(vehicle, truth, lambda t: t >= 1.1))
    assert r["cut_ins"] == 1 and r["cut_ins_missed"] == 0
    assert r["cut_in_warning_lead_s_min"] == pytest.approx(1.5) and r["cut_in_leads_s"] == [pytest.approx(1.5)]
    assert r["false_warnings"] == 0 and r["false_warnings_per_min"] == 0.0


def test_the_lead_counts_from_the_last_warning_run_before_the_crossing(vehicle, truth):
    r = run(cut_in_run(vehicle, truth, lambda t: 0.5 <= t <= 1.0 or 2.0 <= t <= 2.7))
    # both onsets are followed by the crossing within 3 s: neither is false
    assert r["cut_in_warning_lead_s_min"] == pytest.approx(0.6) and r["false_warnings"] == 0


def test_a_cut_in_as_the_ego_passes_a_node_of_the_road_still_counts(vehicle, truth):
    # the ego's lane keeps its id while the road's segment changes under it, on the frame the car crosses
    frames = [(replace(gt, lane=replace(gt.lane, lane_index=("b", "c", 1))) if gt.time_s >= 2.55 else gt, est)
              for gt, est in cut_in_run(vehicle, truth, lambda t: t >= 1.1)]
    r = run(frames)
    assert r["cut_ins"] == 1 and r["cut_in_leads_s"] == [pytest.approx(1.5)]


def test_a_warned_car_seen_in_the_ego_lane_a_frame_before_it_crosses_keeps_its_lead(vehicle, truth):
    # warned from 1.1 s; at 2.5 s its track is already in the ego lane (no longer flagged), the truth crosses at 2.6 s
    frames = []
    for gt, est in cut_in_run(vehicle, truth, lambda t: t >= 1.1):
        if gt.time_s >= 2.45:
            est = [replace(n, lane=0, lateral_m=n.lateral_m + 4.0, cut_in=False, time_to_cross_s=None) for n in est]
        frames.append((gt, est))
    r = run(frames)
    assert r["cut_ins_missed"] == 0 and r["cut_in_leads_s"] == [pytest.approx(1.5)]
    # one that stays in the ego lane in the estimate while the car never crosses is still a false warning
    frames = []
    for gt, est in cut_in_run(vehicle, truth, lambda t: t >= 1.1, seconds=8.0, cross=False):
        if gt.time_s >= 2.45:
            est = [replace(n, lane=0, lateral_m=n.lateral_m + 4.0, cut_in=False, time_to_cross_s=None) for n in est]
        frames.append((gt, est))
    assert run(frames)["false_warnings"] == 1


def test_a_cut_in_never_warned_scores_no_lead_and_is_missed(vehicle, truth):
    for warned in (lambda t: False, lambda t: 0.5 <= t <= 1.0, lambda t: t >= 2.6):
        r = run(cut_in_run(vehicle, truth, warned))
        assert r["cut_ins"] == 1 and r["cut_ins_missed"] == 1 and r["cut_in_warning_lead_s_min"] == 0.0


def test_a_warning_for_a_vehicle_that_keeps_its_lane_is_false(vehicle, truth):
    r = run(cut_in_run(vehicle, truth, lambda t: t >= 1.0, seconds=6.0, cross=False))
    assert r["cut_ins"] == 0 and r["cut_in_warning_lead_s_min"] is None and r["false_warnings"] == 1
    # one onset over 61 frames of 0.1 s
    assert r["false_warnings_per_min"] == pytest.approx(60 / 6.1)
    # an onset less than 3 s before the end is not judged
    r = run(cut_in_run(vehicle, truth, lambda t: t >= 3.5, seconds=6.0, cross=False))
    assert r["false_warnings"] == 0


def test_a_warning_for_a_vehicle_moving_in_behind_the_ego_is_no_cut_in_and_not_false(vehicle, truth):
    frames = []
    for k in range(51):
        gt = truth([vehicle(1, -20.0, 4.04 - 0.8 * k / 10, lateral_speed=-0.8, visible=0, rear_visible=1.0)],
                   time_s=k / 10)
        frames.append((gt, mirrored(gt, cut_in=k >= 11)))
    r = run(frames)
    assert (r["cut_ins"], r["false_warnings"], r["cut_in_warning_lead_s_min"]) == (0, 0, None)


def test_the_ego_changing_lanes_is_no_cut_in(vehicle, truth):
    before = truth([vehicle(1, 30.0, 4.0)], lane_index=("a", "b", 1))
    after = truth([vehicle(1, 30.0, 0.2)], time_s=DT, lane_index=("a", "b", 0))
    assert run([(before, []), (after, [])])["cut_ins"] == 0
    moved = replace(after, lane=replace(after.lane, lane_index=("a", "b", 1)))
    assert run([(before, []), (moved, [])])["cut_ins"] == 1


def test_the_privileged_slot_gets_only_the_truth_keys(vehicle, truth):
    r = run(cut_in_run(vehicle, truth, lambda t: t >= 1.1), vision=False)
    assert r["cut_ins"] == 1 and r["frames"] == 51
    for key in ("recall_ahead", "recall_ahead_by_lane", "counts", "lane_accuracy", "gap_abs_rel_err_by_bin",
                "beside_absent_frames", "cut_ins_missed", "cut_in_warning_lead_s_min", "false_warnings_per_min"):
        assert r[key] is None, key
    assert run([], vision=False).keys() == run([]).keys()


def test_matching_is_one_to_one_inside_the_gate():
    def at(tid, x, lane=0, lateral=0.0):
        return Neighbour(tid, lane, Zone.AHEAD, x, x - 5, 0.0, lateral, 0.0)

    truth = [at(1, 30.0), at(2, 60.0, lane=1)]
    # two tracks on vehicle 1: the nearer gets it; 5 m short at 30 m is outside max(4, 3) m, 5.5 m at 60 m inside 6 m
    assert match_tracks([at(10, 30.5), at(11, 29.0)], truth, 4.0) == [(0, 0)]
    assert match_tracks([at(12, 25.0), at(13, 54.5, lane=1)], truth, 4.0) == [(1, 1)]
    # 1.9 m across is outside the 1.8 m gate, whatever lane the track names
    assert match_tracks([at(14, 30.0, lateral=1.9)], truth, 4.0) == []
    assert match_tracks([at(15, 60.0, lane=0, lateral=2.5)], truth, 4.0) == [(0, 1)]
    assert match_tracks([], truth, 4.0) == [] and match_tracks([at(16, 30.0)], [], 4.0) == []


def crash(vehicle, truth, positions, lateral_speed=0.0, heading=0.0, speed=25.0):
    """Frames 0.1 s apart with vehicle 5 at each of ``positions`` (x, y), the ego touching it on the last."""
    frames = []
    for k, (x, y) in enumerate(positions):
        last = k == len(positions) - 1
        car = vehicle(5, x, y, speed=speed, lateral_speed=lateral_speed, yaw=-heading)
        frames.append((truth([car], time_s=k * DT, heading=heading, crashed=last, collided_with=(5,) if last else ()),
                       []))
    return run(frames)["collisions"]


def test_a_neighbour_moving_over_into_the_ego_is_the_mover(vehicle, truth):
    got = crash(vehicle, truth, [(0.0, 2.5 - 0.1 * k) for k in range(7)], lateral_speed=-1.0)
    assert got == [{"time_s": 0.6, "other_id": 5, "mover": "other", "kind": "side"}]


def test_the_ego_rear_ending_or_moving_over_is_the_mover_and_a_car_behind_running_in_is(vehicle, truth):
    assert crash(vehicle, truth, [(6.0 - 0.2 * k, 0.0) for k in range(6)], speed=23.0)[0] | {"time_s": 0} == {
        "time_s": 0, "other_id": 5, "mover": "ego", "kind": "rear-end"}
    assert crash(vehicle, truth, [(-6.0 + 0.2 * k, 0.0) for k in range(6)], speed=27.0)[0]["mover"] == "other"
    # the ego heading 0.05 rad left (1.25 m/s sideways) into a car in the next lane
    side = crash(vehicle, truth, [(0.0, 2.1 - 0.0 * k) for k in range(4)], heading=0.05)[0]
    assert (side["mover"], side["kind"]) == ("ego", "side")


def test_a_crash_with_no_known_vehicle_is_recorded_once_without_a_mover(truth):
    frames = [(truth(time_s=k * DT, crashed=k >= 2), []) for k in range(5)]
    assert run(frames)["collisions"] == [{"time_s": 0.2, "other_id": None, "mover": None, "kind": None}]


def test_a_warning_held_while_a_car_waits_on_the_line_is_justified(vehicle, truth):
    # 30 m ahead in lane +1: on the line (shifted 1 m towards the ego lane) for 4 s, then over it; warned throughout
    frames = []
    for k in range(60):
        t = k * DT
        y = 3.0 if t < 4.0 else 3.0 - 1.0 * (t - 4.0)
        gt = truth([vehicle(1, 30.0, y, lateral_speed=0.0 if t < 4.0 else -1.0)], time_s=t)
        frames.append((gt, mirrored(gt, cut_in=True)))
    r = run(frames)
    assert r["cut_ins"] == 1 and r["false_warnings"] == 0
    assert r["cut_in_warning_lead_s_min"] > 4.0


def test_a_warning_that_never_ends_in_a_crossing_is_false(vehicle, truth):
    frames = []
    for k in range(50):
        gt = truth([vehicle(1, 30.0, 3.0)], time_s=k * DT)
        frames.append((gt, mirrored(gt, cut_in=True)))
    r = run(frames)
    assert r["cut_ins"] == 0 and r["false_warnings"] == 1


def test_a_car_that_crosses_soon_after_it_comes_into_view_is_not_scored_for_its_lead(vehicle, truth):
    # already moving over when first seen, 1.2 s before it crosses: counted, not scored
    frames = []
    for k in range(20):
        t = k * DT
        gt = truth([vehicle(1, 30.0, 3.2 - 1.0 * t, lateral_speed=-1.0)], time_s=t)
        frames.append((gt, []))
    r = run(frames)
    assert r["cut_ins"] == 1 and r["cut_ins_unscored"] == 1
    assert r["cut_ins_missed"] == 0 and r["cut_in_warning_lead_s_min"] is None


def test_a_car_that_turns_back_halfway_out_of_the_ego_lane_is_no_cut_in(vehicle, truth):
    # from the ego lane's centre out to 2.4 m (its near side still 0.6 m inside the 4 m lane), then back
    path = [0.3 * k for k in range(9)] + [2.4 - 0.3 * k for k in range(1, 9)]
    frames = [(truth([vehicle(1, 30.0, y)], time_s=k * DT), []) for k, y in enumerate([0.0] * 30 + path)]
    r = run(frames)
    assert r["cut_ins"] == 0 and r["cut_ins_missed"] == 0
    # the same car going on until it is clear of the lane (3 m), then coming back, cuts in
    out = [0.3 * k for k in range(12)] + [3.3 - 0.3 * k for k in range(1, 12)]
    frames = [(truth([vehicle(1, 30.0, y)], time_s=k * DT), []) for k, y in enumerate([0.0] * 30 + out)]
    assert run(frames)["cut_ins"] == 1


@pytest.mark.parametrize("onset_s, false", [(3.0, 0), (3.8, 1)])
def test_a_warning_begun_just_after_its_car_crossed_is_late_not_false(vehicle, truth, onset_s, false):
    # the car crosses between 2.5 and 2.6 s; a warning from 3.0 s is late (within 1 s), one from 3.8 s is false
    r = run(cut_in_run(vehicle, truth, lambda t: t >= onset_s, seconds=8.0))
    assert r["cut_ins"] == 1 and r["cut_ins_missed"] == 1 and r["false_warnings"] == false
