"""The neighbours part on a hand-made scene: a box per track on the true lane, coloured by lane, a predicted one
fainter, a cut-in highlighted with its time to crossing; the blind zone beside the ego; each lane's nearest gap and
relative speed beside the truth's; one warning when a cut-in starts; the boxes each rig measured on its image."""

import math
from types import SimpleNamespace

import numpy as np
import pytest
import rerun as rr

from percept.drive.scoring import StepTruth
from percept.neighbours import NeighbourDebug, TrackerConfig
from percept.review import ColumnBuffer, PartContext
from percept.review.parts.lane_view import nearest_truths, true_lane
from percept.review.parts.neighbours import CUT_IN_RGB, LANE_RGB, LOG, PART
from percept.sensors import ImuSample, Neighbour, Neighbours, ObjectKind, Pose2D, StereoRig, Zone, rear_rig
from percept.sims.ground_truth import GroundTruth, LaneTruth, ObjectTruth

WIDTH_M = 3.6
"""The hand-made lane's width [m] (not the 3.75 m default, so that the drawing must read it from the truth)."""


def tracks(cut_in: bool = True) -> Neighbours:
    """Four tracks: ahead in the ego lane (front rig), ahead on the left cutting in (front rig), beside on the
    right (predicted only), behind on the right (rear rig)."""
    return Neighbours((
        Neighbour(1, 0, Zone.AHEAD, 30.0, 25.0, -2.0, 0.1, 0.0, camera="front", box_px=(300, 200, 360, 240)),
        Neighbour(2, 1, Zone.AHEAD, 15.0, 10.0, -1.0, -0.8, -0.6, camera="front", box_px=(100, 190, 200, 250),
                  cut_in=cut_in, time_to_cross_s=1.4 if cut_in else None),
        Neighbour(3, -1, Zone.BESIDE, -1.0, 0.0, 0.5, 0.0, 0.0, sigma_x_m=1.5),
        Neighbour(4, -1, Zone.BEHIND, -20.0, 15.0, 3.0, 0.2, 0.0, camera="rear", box_px=(400, 200, 450, 230)),
    ))


def vehicle(obj_id: int, x: float, y: float, speed: float, box=None, rear_box=None) -> ObjectTruth:
    return ObjectTruth(obj_id, ObjectKind.VEHICLE, box, 1.0 if box else 0.0, abs(x), (x, y, 0.75), (5.0, 2.0, 1.5),
                       0.0, speed, rear_box_px=rear_box, rear_visible=1.0 if rear_box else 0.0)


def truth(t: float = 0.0, offset_m: float = 0.3) -> StepTruth:
    """The ego at 25 m/s, ``offset_m`` left of its lane's centre; the true vehicles of ``tracks``, and one too far."""
    objects = (vehicle(11, 30.2, -offset_m, 23.0, box=(300, 200, 360, 240)),
               vehicle(12, 15.1, WIDTH_M - 0.8 - offset_m, 24.0, box=(100, 190, 200, 250)),
               vehicle(13, -1.0, -WIDTH_M - offset_m, 25.5),
               vehicle(14, -20.3, -WIDTH_M - offset_m, 28.0, rear_box=(400, 200, 450, 230)),
               vehicle(15, 200.0, -offset_m, 20.0))
    imu = ImuSample(np.zeros(3), np.zeros(3))
    gt = GroundTruth(t, Pose2D(100.0 + 25.0 * t, 0.0, 0.0), 25.0, LaneTruth(offset_m, 0.0, 0.0, WIDTH_M, ("a", "b", 1)),
                     objects, np.zeros((2, 2), np.float32), imu, False, ())
    return StepTruth(gt, [], None, 0.0, 0.0)


class Capture(ColumnBuffer):
    """The rows a part sends through the buffer, kept by path (the last row of each)."""

    def __init__(self):
        super().__init__("sim_time")
        self.last: dict[str, tuple[type, dict]] = {}

    def add(self, path, archetype, **components):
        super().add(path, archetype, **components)
        self.last[path] = (archetype, components)


class Logged:
    """A stand-in for the recording stream: what ``rec.log`` was given, in order."""

    def __init__(self):
        self.logs: list[tuple[str, object]] = []

    def log(self, path, entity, **kwargs):
        self.logs.append((path, entity))


def context(buffer: Capture, image: bool = True, rear_image: bool = True) -> PartContext:
    rig = StereoRig()
    return PartContext("neighbours", rig, buffer, image=image, image_scale=0.5, rear_rig=rear_rig(rig),
                       rear_image=rear_image)


def draw(estimate=None, debug=None, ctx=None, step_truth=None):
    buffer = Capture()
    ctx = ctx or context(buffer)
    rec = Logged()
    PART(rec, ctx, tracks() if estimate is None else estimate, debug, step_truth or truth())
    return ctx.buffer, rec


def test_each_track_is_a_box_on_the_true_lane_coloured_by_lane():
    buffer, _ = draw()
    kind, measured = buffer.last["world/ego/neighbours/measured"]
    assert kind is rr.Boxes3D
    # the ego lane's centre is 0.3 m right of the ego (offset +0.3): track 1 at 0.1 m left of it, track 4 a lane right
    np.testing.assert_allclose(np.asarray(measured["centers"])[:, :2], [[30.0, -0.2], [-20.0, -WIDTH_M - 0.1]],
                               atol=1e-9)
    assert [tuple(c[:3]) for c in measured["colors"]] == [LANE_RGB[0], LANE_RGB[-1]]
    assert "25.0 m ahead" in measured["labels"][0] and "-2.0 m/s" in measured["labels"][0]
    _, predicted = buffer.last["world/ego/neighbours/predicted"]
    faint = predicted["colors"][0]
    assert len(faint) == 4 and faint[3] < 255 and sum(faint[:3]) < sum(LANE_RGB[-1])
    assert "predicted" in predicted["labels"][0] and "beside" in predicted["labels"][0]


def test_a_cut_in_is_highlighted_with_its_time_to_crossing():
    buffer, _ = draw()
    _, cut = buffer.last["world/ego/neighbours/cut_in"]
    assert tuple(cut["colors"][0][:3]) == CUT_IN_RGB
    assert cut["labels"][0].startswith("CUT-IN 1.4 s")
    np.testing.assert_allclose(cut["centers"][0][:2], [15.0, WIDTH_M - 0.8 - 0.3], atol=1e-9)
    assert cut["radii"][0] > buffer.last["world/ego/neighbours/measured"][1]["radii"][0]


def test_the_blind_zone_is_drawn_in_the_lanes_beside_from_the_trackers_band():
    buffer, _ = draw()
    kind, zone = buffer.last["world/ego/neighbours/blind_zone"]
    assert kind is rr.LineStrips3D and len(zone["strips"]) == 2
    cfg = TrackerConfig()
    for strip, side in zip(zone["strips"], (-1, 1)):
        assert strip[:, 0].min() == pytest.approx(cfg.blind_behind_m)
        assert strip[:, 0].max() == pytest.approx(cfg.blind_ahead_m)
        lateral = np.sort(np.unique(np.round(strip[:, 1] + 0.3, 9)))  # from the lane's centre line
        np.testing.assert_allclose(lateral, np.sort([side * WIDTH_M / 2, side * 3 * WIDTH_M / 2]))
        assert np.all(strip[:, 2] == 0)
    # the right side holds the predicted track 3: drawn in another colour than the empty left side
    assert zone["colors"][0] != zone["colors"][1]


def scalar(buffer: Capture, path: str) -> float | None:
    kind, row = buffer.last[path]
    return None if kind is rr.Clear else row["scalars"][0]


def test_each_lanes_nearest_gap_and_relative_speed_beside_the_truths():
    buffer, _ = draw()
    assert scalar(buffer, "neighbours/gap_ahead_m/ego") == 25.0
    assert scalar(buffer, "neighbours/gap_ahead_m/truth_ego") == pytest.approx(25.2)
    assert scalar(buffer, "neighbours/gap_ahead_m/left") == 10.0
    assert scalar(buffer, "neighbours/gap_ahead_m/truth_left") == pytest.approx(10.1)
    assert scalar(buffer, "neighbours/gap_behind_m/right") == 15.0
    assert scalar(buffer, "neighbours/gap_behind_m/truth_right") == pytest.approx(15.3)
    assert scalar(buffer, "neighbours/rel_speed_ahead_mps/truth_ego") == pytest.approx(-2.0)
    assert scalar(buffer, "neighbours/rel_speed_behind_mps/right") == 3.0
    # no vehicle ahead on the right, none behind on the left: the series break there
    assert scalar(buffer, "neighbours/gap_ahead_m/right") is None
    assert scalar(buffer, "neighbours/gap_behind_m/truth_left") is None


def test_the_truths_nearest_per_lane_skips_what_is_beside_or_out_of_range():
    t = truth()
    near = nearest_truths(t, true_lane(t), ahead_m=80.0, behind_m=50.0)
    assert set(near) == {(0, Zone.AHEAD), (1, Zone.AHEAD), (-1, Zone.BEHIND)}
    assert true_lane(SimpleNamespace(truth=SimpleNamespace(lane=None))).width_m == 3.75


def warnings(rec: Logged) -> list[rr.TextLog]:
    return [e for p, e in rec.logs if p == LOG]


def test_a_warning_is_logged_once_when_a_cut_in_starts_and_a_line_when_it_ends():
    buffer = Capture()
    ctx = context(buffer)
    logs = []
    for estimate in (tracks(cut_in=False), tracks(), tracks(), tracks(cut_in=False)):
        rec = Logged()
        PART(rec, ctx, estimate, None, truth())
        logs.append(warnings(rec))
    assert [len(lg) for lg in logs] == [0, 1, 0, 1]
    start = str(logs[1][0].text.as_arrow_array()[0])
    assert "cut-in: #2 from the left lane" in start and "1.4 s" in start
    assert logs[1][0].level.as_arrow_array()[0].as_py() == "WARN"


def on_image(rec: Logged, path: str):
    found = [e for p, e in rec.logs if p == path]
    return found[-1] if found else None


def test_each_rig_draws_the_tracks_it_measured_on_its_own_image():
    debug = NeighbourDebug({"front": [], "rear": []}, {"front": 0, "rear": 0})
    buffer, rec = draw(debug=debug)
    front = on_image(rec, "world/ego/camera/left/neighbours/tracks")
    rear = on_image(rec, "world/ego/camera/rear_left/neighbours/tracks")
    assert front is not None and rear is not None
    # stored at half scale: track 1's box (300, 200, 360, 240) -> centre (165, 110), half size (15, 10)
    np.testing.assert_allclose(front.centers.as_arrow_array().to_pylist()[0], [165.0, 110.0])
    assert len(front.centers.as_arrow_array()) == 2 and len(rear.centers.as_arrow_array()) == 1
    # no detections this frame: those entities are cleared
    assert buffer.last["world/ego/camera/left/neighbours/detections"][0] is rr.Clear


def test_without_images_this_frame_nothing_is_drawn_on_them_and_no_estimate_draws_no_tracks():
    buffer = Capture()
    buffer_out, rec = draw(ctx=context(buffer, image=False, rear_image=False))
    assert not [p for p, _ in rec.logs if "camera" in p]
    assert not [p for p in buffer_out.last if "camera" in p]
    empty = Capture()
    rec = Logged()
    PART(rec, context(empty), None, None, truth())
    assert all(empty.last[f"world/ego/neighbours/{n}"][0] is rr.Clear for n in ("measured", "predicted", "cut_in"))
    assert scalar(empty, "neighbours/gap_ahead_m/truth_ego") == pytest.approx(25.2)
    assert math.isclose(scalar(empty, "neighbours/gap_ahead_m/truth_left"), 10.1)
