"""The rear camera in a recording: with a rear rig, its left image is stored as its own camera at the forward image's
rate, with the true boxes on it and the neighbours part's tracks; without the rig, or on frames without its pair,
nothing of it is stored. Hand-made frames and truth."""

import numpy as np

from percept.drive import TASKS
from percept.drive.agent import AgentStep
from percept.review import RunRecorder
from percept.review.context import REAR_CAMERA
from percept.sensors import Frame, ImuSample, StereoRig, rear_rig

from .test_neighbours import tracks, truth
from .test_recorder import columns_by_entity, verify

NEIGHBOURS = tuple(t for t in TASKS if t.recorder and t.recorder.endswith("neighbours:PART"))
REAR = f"/{REAR_CAMERA}"


def frame(i: int, rear: bool) -> Frame:
    """Frame ``i`` of a 15 Hz run: grey 640x480 images, the rear pair when ``rear``."""
    img = np.full((480, 640, 3), 90, np.uint8)
    return Frame(i, i / 15, img, img, ImuSample(np.zeros(3), np.zeros(3)), 25.0,
                 img if rear else None, img if rear else None)


def record(path, rig_behind: bool, rear_frames: bool, frames: int = 15) -> dict:
    """A 1 s recording of the hand-made scene; its columns by entity."""
    rig = StereoRig()
    recorder = RunRecorder(path, rig, [np.array([[0.0, 0.0], [300.0, 0.0]])], NEIGHBOURS,
                           rear_rig=rear_rig(rig) if rig_behind else None)
    for i in range(frames):
        estimate = tracks(cut_in=i >= 5)
        step = AgentStep(0.0, 0.0, {"neighbours": estimate}, {"neighbours": None}, {}, {})
        recorder.log_step(frame(i, rear_frames), truth(i / 15), step)
    assert recorder.close() == path
    verify(path)
    return columns_by_entity(path)


def images(cols: dict, entity: str) -> int:
    return cols.get(entity, {}).get("EncodedImage:blob", 0)


def test_a_rear_rig_stores_its_left_image_with_the_true_boxes_and_the_tracks_it_measured(tmp_path):
    cols = record(tmp_path / "rear.rrd", rig_behind=True, rear_frames=True)
    # the same rate as the forward image: 5 Hz over 1 s; what is drawn on an image, a row with each stored image
    assert images(cols, REAR) == images(cols, "/world/ego/camera/left") == 5
    assert cols[f"{REAR}/objects"]["Boxes2D:half_sizes"] == 5  # vehicle 14's true box
    assert cols[f"{REAR}/neighbours/tracks"]["Boxes2D:half_sizes"] == 5  # track 4, measured by the rear rig
    assert cols["/world/ego/camera/left/neighbours/tracks"]["Boxes2D:half_sizes"] == 5  # tracks 1 and 2
    for entity in ("/world/ego/neighbours/measured", "/world/ego/neighbours/predicted", "/world/ego/neighbours/cut_in",
                   "/world/ego/neighbours/blind_zone", "/neighbours/gap_ahead_m/ego",
                   "/neighbours/gap_behind_m/truth_right", "/neighbours/rel_speed_ahead_mps/left"):
        assert entity in cols, entity
    assert cols["/neighbours/warnings"]["TextLog:text"] == 1  # the cut-in from frame 5 on, warned once


def test_without_a_rear_rig_or_its_pair_no_rear_image_is_stored(tmp_path):
    for name, rig_behind, rear_frames in (("none.rrd", False, True), ("dropped.rrd", True, False)):
        cols = record(tmp_path / name, rig_behind, rear_frames, frames=4)
        assert images(cols, "/world/ego/camera/left") == 2
        assert images(cols, REAR) == 0
        assert not [e for e in cols if e.startswith(f"{REAR}/")], name
