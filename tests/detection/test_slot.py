"""The vision pedestrians slot: in the closed loop it stops for a crossing person and its reported people are
scored against the truth; dropped frames, a black frame and a NaN wheel speed or yaw rate degrade gracefully."""

import math
from dataclasses import replace

import numpy as np
import pytest

from percept.detection import PedestrianSlot, PersonTrack
from percept.drive import DriveConfig, run_drive
from percept.sensors import EgoPath, Frame, ImuSample, StereoRig
from percept.sims import WorldConfig, check_condition


@pytest.fixture(scope="module")
def crossing_run():
    # seed 3: a person crosses in front of the ego within the first 32 s
    return run_drive(DriveConfig(WorldConfig("crossing", seed=3), duration_s=32.0,
                                 sources={"pedestrians": "vision"}, default="privileged"))


@pytest.mark.slow
def test_the_car_stops_for_the_crossing_person_on_vision(crossing_run):
    r = crossing_run
    p = r["pedestrians"]
    assert r["pedestrian_collisions"] == 0 and r["collisions"] == 0
    assert p["stops"][0], p  # the first crossing (a second one is still on its way when the run ends)
    assert p["false_stops"] == 0 and p["verge_brakes"] == 0 and r["longitudinal"]["phantom_brakes"] == 0
    assert p["detector"] == "sim" and r["timing_ms"]["pedestrians"] > 0


@pytest.mark.slow
def test_its_people_are_scored_against_the_truth(crossing_run):
    p = crossing_run["pedestrians"]
    assert p["recall"] >= 0.8 and p["precision"] >= 0.8 and p["fppi"] <= 0.1, p
    assert set(p["recall_by_height"]) == {"24-40", ">=40"}
    assert 20.0 <= p["first_detection_range_m"] <= 41.0


def frame(index: int, left, speed: float = 10.0) -> Frame:
    return Frame(index, index / 15, left, left, ImuSample(np.zeros(3), np.zeros(3)), speed)


def test_dropped_and_black_frames_and_nan_wheel_speed_or_yaw_rate_degrade_gracefully():
    slot = PedestrianSlot(StereoRig(), 1 / 15)
    path = EgoPath.straight(10.0)
    black = np.zeros((480, 640, 3), np.uint8)
    request, debug = slot.step(frame(0, black), {EgoPath: path})
    assert request is None and debug.detections == () and debug.stats.windows > 0
    request, debug = slot.step(frame(1, None), {EgoPath: path})  # dropped: nothing searched
    assert request is None and debug.stats is None and debug.levels == ()
    request, debug = slot.step(frame(2, black, speed=math.nan), {})  # no path: a straight corridor
    assert request is None and slot.motion.last.speed_mps == 10.0  # the last good wheel speed is kept
    turning = Frame(3, 3 / 15, black, black, ImuSample(np.zeros(3), np.array([0.0, 0.0, 0.1])), 10.0)
    slot.step(turning, {EgoPath: path})
    broken = Frame(4, 4 / 15, black, black, ImuSample(np.zeros(3), np.array([0.0, 0.0, np.nan])), 10.0)
    request, _ = slot.step(broken, {EgoPath: path})
    assert request is None and slot.motion.last.yaw_rate_rps == 0.1  # and the last good yaw rate
    with pytest.raises(ValueError, match="sweep_frames"):
        PedestrianSlot(StereoRig(), 1 / 15, sweep_frames=0)
    with pytest.raises(ValueError, match="far_sweep_frames must be at least 1"):
        PedestrianSlot(StereoRig(), 1 / 15, far_sweep_frames=0)


def test_the_far_fields_levels_are_searched_more_often_than_the_near_ones():
    """Every level once in its period: the far field's (people up to far_person_px tall) in far_sweep_frames frames,
    the others in sweep_frames."""
    slot = PedestrianSlot(StereoRig(), 1 / 15, sweep_frames=6, far_sweep_frames=3, far_person_px=50.0)
    black = np.zeros((480, 640, 3), np.uint8)
    seen = [slot.step(frame(i, black), {EgoPath: EgoPath.straight(10.0)})[1].levels for i in range(12)]
    heights = 96 * slot.search.scales
    for k, h in enumerate(heights):
        frames = [i for i, levels in enumerate(seen) if k in levels]
        assert frames == list(range(k % (3 if h <= 50 else 6), 12, 3 if h <= 50 else 6))
    assert 0 < sum(heights <= 50) < len(heights)


def test_by_default_the_levels_where_crossing_people_are_first_found_are_searched_every_third_frame():
    """The defaults: the three smallest levels (people up to 34.6 px, the only ones that reach the 28.3 m and more
    at which every crossing person of the evaluation seeds is first found) every third frame, the others every
    eighth."""
    slot = PedestrianSlot(StereoRig(), 1 / 15)
    assert slot.periods == (3, 3, 3) + (8,) * (len(slot.search.scales) - 3)
    assert all(slot.search.depths[k][1] < 28.3 for k in range(3, len(slot.search.scales)))
    assert all(slot.search.depths[k][1] > 28.3 for k in range(3))


@pytest.mark.slow
def test_in_rain_a_far_person_seen_in_lone_windows_is_stopped_for():
    # rain, seed 10: the third person crosses 40-10 m ahead while the ego drives at 55 km/h; in rain the far field
    # often gives one window, which grouping drops: without lone windows verified by stereo the person is first
    # detected at 10 m and hit (at 30.1 s); by 33 s the car has come to a stop before them
    r = run_drive(DriveConfig(WorldConfig("crossing", seed=10, condition=check_condition("rain")), duration_s=33.0,
                              sources={"pedestrians": "vision"}, default="privileged"))
    p = r["pedestrians"]
    assert r["pedestrian_collisions"] == 0 and r["collisions"] == 0
    assert len(p["stops"]) == 3 and all(p["stops"]), p
    # a false window or two in a hundred frames, as the evaluations' means: one window more must not fail the test
    assert p["recall_by_height"]["24-40"] >= 0.7 and p["fppi"] <= 0.03, p


def track(tid: int, x: float, y: float, vy: float = 0.0, stereo_hits: int = 5, standing=None, hits: int = 20,
          vx: float = 0.0, too_fast: bool = False):
    """A confirmed, seen track of a person at (x, y) walking at (vx, vy) [m/s] (sigma of vy 0.1 m/s; its free motion
    the same, sigma 0.3 m/s); too_fast: its detections have shown a vehicle's speed."""
    return PersonTrack(tid, (x, y), (vx, vy), 0.1, 1.75, (300.0, 200.0, 320.0, 260.0), 1.0, hits, 0, True, True,
                       standing if standing is not None else (x, y), stereo_hits, float(np.hypot(vx, vy)), 0.3,
                       too_fast)


def test_only_tracks_the_stereo_pair_has_placed_on_the_road_ask_for_braking():
    slot = PedestrianSlot(StereoRig(), 1 / 15)
    path = EgoPath.straight(10.0)
    request, rid = slot.request([track(1, 15.0, 0.5, stereo_hits=0), track(2, 25.0, -0.5)], path, 10.0)
    assert rid == 2 and request.reason == "pedestrian in the path"
    assert request.stop_before_m == pytest.approx(25.0 - slot.cam_x)
    assert slot.request([track(1, 15.0, 0.5, stereo_hits=0)], path, 10.0) == (None, None)


def test_a_track_that_has_shown_a_vehicles_speed_asks_for_no_braking():
    # highway seed 1 at night: a car's corner 35 m ahead in the path, its person filter at 1.9 m/s, its detections
    # at 21 m/s: the car braked from 26 m/s to a standstill for it
    slot = PedestrianSlot(StereoRig(), 1 / 15)
    path = EgoPath.straight(26.0)
    assert slot.request([track(1, 36.0, 0.5, vx=1.9, too_fast=True)], path, 26.0) == (None, None)
    # a person running across at 3 m/s is still one
    request, rid = slot.request([track(1, 17.8, 1.8, vx=0.5, vy=-3.0)], path, 20.0)
    assert rid == 1 and request.reason == "pedestrian stepping into the path"


def test_a_young_track_far_ahead_waits_for_its_motion_and_a_near_one_does_not():
    # curves seed 4: a car's corner 40 m ahead in the path, confirmed after three detections with its free motion at
    # 29 +- 15 m/s; at 20 m/s the car can wait for the motion: a stop at 6.5 m/s^2 takes 31 m (and the 4 m margin),
    # a frame 1.3 m
    slot = PedestrianSlot(StereoRig(), 1 / 15)
    path = EgoPath.straight(20.0)
    far = slot.cam_x + 40.0
    assert slot.request([track(1, far, 0.3, hits=3)], path, 20.0) == (None, None)
    assert slot.request([track(1, far, 0.3, hits=8)], path, 20.0)[1] == 1  # its motion known: a person
    near = slot.cam_x + 30.0
    assert slot.request([track(1, near, 0.3, hits=3)], path, 20.0)[1] == 1  # no room left to wait


class _Tracks:
    """A stand-in tracker whose tracks the test sets each frame."""

    def __init__(self, rig, dt_s):
        self.rig, self.dt_s, self.now = rig, dt_s, []

    def predict(self, speed, yaw_rate):
        return []

    def update(self, *args, **kwargs):
        return self.now


def test_the_request_is_withdrawn_once_the_track_asked_for_moves_like_a_vehicle():
    rig = StereoRig()
    slot = PedestrianSlot(rig, 1 / 15)
    slot.tracker = _Tracks(rig, 1 / 15)
    black = np.zeros((rig.camera.height, rig.camera.width, 3), np.uint8)
    x = slot.cam_x + 30.0
    slot.tracker.now = [track(7, x, 0.3)]
    request, dbg = slot.step(frame(0, black, speed=20.0), {})
    assert request.obj_id == 7 and not request.withdrawn and dbg.request_track == 7
    slot.tracker.now = [track(7, x, 0.3, vx=18.0, too_fast=True)]
    request, dbg = slot.step(frame(1, black, speed=20.0), {})
    assert request.withdrawn and request.obj_id == 7 and dbg.request_track is None
    request, _ = slot.step(frame(2, black, speed=20.0), {})
    assert request is None  # withdrawn once


def test_no_withdrawal_while_a_person_asked_for_is_out_of_sight():
    rig = StereoRig()
    slot = PedestrianSlot(rig, 1 / 15)
    slot.tracker = _Tracks(rig, 1 / 15)
    black = np.zeros((rig.camera.height, rig.camera.width, 3), np.uint8)
    slot.tracker.now = [track(1, slot.cam_x + 20.0, 0.0)]
    assert slot.step(frame(0, black, speed=10.0), {})[0].obj_id == 1
    slot.tracker.now = [track(2, slot.cam_x + 35.0, 0.2)]  # the person lost from view; a corner asked for
    assert slot.step(frame(1, black, speed=10.0), {})[0].obj_id == 2
    slot.tracker.now = [track(2, slot.cam_x + 35.0, 0.2, vx=15.0, too_fast=True)]
    assert slot.step(frame(2, black, speed=10.0), {})[0] is None  # the stop committed to for the person stays


def young(tid, x, free_mps, sigma_mps):
    """A track three detections old whose free motion reads free_mps +- sigma_mps."""
    return replace(track(tid, x, 0.2, hits=3), free_speed_mps=free_mps, sigma_free_speed_mps=sigma_mps)


def test_a_young_track_whose_free_motion_reads_a_vehicles_speed_waits_longer():
    # curves seed 17: a car's corner 32.5 m ahead in the path, confirmed after three detections with its free motion
    # at 16.4 +- 5.0 m/s, asked for at 18.8 m/s (a stop at 6.5 m/s^2 and the 4 m margin took the room left); a frame
    # later its free motion showed the vehicle (18.2 +- 3.5) and the request was withdrawn
    slot = PedestrianSlot(StereoRig(), 1 / 15)
    path = EgoPath.straight(18.8)
    x = slot.cam_x + 32.5
    assert slot.request([young(1, x, 16.4, 5.0)], path, 18.8) == (None, None)  # a stop at 7.5 m/s^2 still fits
    assert slot.request([young(1, x, 3.0, 5.0)], path, 18.8)[1] == 1  # read as a walk: no longer
    assert slot.request([young(1, x - 2.5, 16.4, 5.0)], path, 18.8)[1] == 1  # two frames on: no room left


def test_a_young_track_asked_for_and_lost_is_withdrawn_only_if_it_moved_like_a_vehicle():
    # curves seed 8: a corner 36 m ahead asked for after four detections (free motion 16.3 +- 8.3 m/s), then lost
    # from view on the bend: the stop committed to for it brought the car from 19.5 m/s to a standstill
    rig = StereoRig()
    black = np.zeros((rig.camera.height, rig.camera.width, 3), np.uint8)
    for free, withdrawn in (((16.3, 8.3), True), ((3.0, 8.3), False)):
        slot = PedestrianSlot(rig, 1 / 15)
        slot.tracker = _Tracks(rig, 1 / 15)
        slot.tracker.now = [young(7, slot.cam_x + 30.0, *free)]
        assert slot.step(frame(0, black, speed=19.5), {})[0].obj_id == 7
        slot.tracker.now = []
        request = slot.step(frame(1, black, speed=19.0), {})[0]
        assert (request is not None and request.withdrawn) == withdrawn, free


def test_a_young_track_once_asked_for_does_not_go_back_to_waiting():
    rig = StereoRig()
    slot = PedestrianSlot(rig, 1 / 15)
    slot.tracker = _Tracks(rig, 1 / 15)
    black = np.zeros((rig.camera.height, rig.camera.width, 3), np.uint8)
    slot.tracker.now = [young(7, slot.cam_x + 31.0, 16.0, 10.0)]
    assert slot.step(frame(0, black, speed=19.5), {})[0].obj_id == 7  # no room left to wait at 19.5 m/s
    # braking, the car has room again at 17 m/s: the track stays asked for
    assert slot.step(frame(1, black, speed=17.0), {})[0].obj_id == 7

def test_a_track_not_walking_is_judged_where_it_was_last_seen():
    slot = PedestrianSlot(StereoRig(), 1 / 15)
    path = EgoPath.straight(10.0)
    # carried into the corridor by a speed not yet trusted (5 detections), last seen on the verge: no braking
    assert slot.request([track(1, 15.0, 1.0, vy=-1.2, hits=5, standing=(15.0, 3.5))], path, 10.0) == (None, None)
    # the same track once its walk is trusted: in the path
    request, _ = slot.request([track(1, 15.0, 1.0, vy=-1.2, standing=(15.0, 3.5))], path, 10.0)
    assert request.reason == "pedestrian in the path"


def test_the_request_closes_at_the_ego_speed_whatever_the_tracks_own_x_speed():
    # crossing seed 7: a person crossing 35 m ahead, the closing speed read 0.7-1.3 m/s short of the car's (the
    # track's x speed, from depths whose noise grows with Z^2);
    # the request's range rate is the ego's speed alone, as for a person standing on the road
    slot = PedestrianSlot(StereoRig(), 1 / 15)
    path = EgoPath.straight(12.6)
    for vx in (0.7, -0.5, 0.0):
        request, _ = slot.request([track(1, 35.0, 0.5, vx=vx, vy=-1.2)], path, 12.6)
        assert request.range_rate_mps == -12.6


WARM_CHECK = """
from percept.compiled import dispatchers
from percept.detection import blocks, hog, pyramid, stereo_range
from percept.drive import SlotContext, TruthFeed
from percept.drive.tasks import TASKS
from percept.sensors import EgoPath
from percept.sims import SimWorld, WorldConfig
from percept.sims.coords import hw_pose
kernels = dispatchers(blocks, hog, pyramid, stereo_range)
world = SimWorld(WorldConfig("crossing", seed=1, autopilot=True))
feed = TruthFeed()
ctx = SlotContext(world.cfg.rig, world.dt, None, feed, start_pose=hw_pose(world.ego))
tasks = {t.name: t for t in TASKS}
lateral, slot = tasks["lanes"].privileged(ctx), tasks["pedestrians"].vision(ctx)
before = [len(k.signatures) for k in kernels]
grouped = lone = stereo = 0
for _ in range(60):
    frame, feed.truth = world.observe()
    request, debug = slot.step(frame, {EgoPath: lateral.step(frame, {})[0]})
    grouped += sum(d.windows > 1 for d in debug.detections)
    lone += sum(d.windows == 1 for d in debug.detections)
    stereo = max([stereo] + [t.stereo_hits for t in debug.tracks])
    world.step()
print(len(kernels), min(before), grouped, lone, stereo, [len(k.signatures) for k in kernels] == before)
"""


@pytest.mark.slow
def test_the_slot_loads_its_compiled_passes_when_built_not_in_a_frame():
    """The HOG blocks', the window sums', the grouping's and the stereo match's compiled passes, in a fresh
    process."""
    import subprocess
    import sys

    out = subprocess.run([sys.executable, "-c", WARM_CHECK], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    count, least, grouped, lone, stereo, unchanged = out.stdout.split()
    # every kernel loaded by the slot's construction; grouped and lone detections and stereo matches came up, so
    # every pass ran
    assert int(count) == 6 and int(least) >= 1 and int(grouped) > 5 and int(lone) > 0 and int(stereo) > 3
    assert unchanged == "True"
