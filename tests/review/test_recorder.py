"""The run recording: every task's part is recorded, objects ride under the ego, the camera options change what is
stored, a finished recording has its RRD footer, and an interrupted recording (kept as streamed, without one) never
replaces a finished one. Checked with the rerun CLI (`rrd verify`, `rrd print`)."""

import os
import re
import shutil
import subprocess
from collections import defaultdict
from pathlib import Path

import pytest

from percept.cli.view_cmd import rerun_executable
from percept.drive import TASKS, DriveConfig, Task, run_drive
from percept.review import RecordOptions, RunRecorder
from percept.review import recorder as recorder_module
from percept.review.recorder import resolve_part
from percept.sensors import StereoRig
from percept.sims import WorldConfig

ENV = {**os.environ, "RERUN_ANALYTICS": "0"}
CHUNK = re.compile(r"with (\d+) rows .* - (\S+) - data columns: \[([^\]]*)\]")
COMMON = ["/world/road", "/world/ego", "/world/ego/body", "/world/ego/camera/left", "/world/ego/objects",
          "/world/ego/camera/left/objects", "/world/trajectory", "/control/speed_mps/truth",
          "/control/accel_mps2/command", "/control/steering_rad/command", "/control/limits"]
TASK_ENTITIES = {
    "lanes": ["/lanes/offset_m/truth", "/lanes/offset_m/estimate", "/lanes/heading_rad/estimate",
              "/lanes/curvature_1pm/truth", "/world/ego/lanes/path", "/world/ego/camera/left/lanes/boundaries"],
    "longitudinal": ["/longitudinal/range_m/truth", "/longitudinal/range_m/estimate",
                     "/longitudinal/range_rate_mps/estimate", "/longitudinal/ttc_s/estimate",
                     "/world/ego/longitudinal/lead"],
    "pedestrians": ["/pedestrians/stop_before_m/estimate", "/pedestrians/stop_before_m/truth",
                    "/world/ego/pedestrians/stop"],
    "odometry": ["/odometry/position_error_m/error", "/odometry/speed_mps/estimate", "/world/odometry/trail",
                 "/world/odometry/pose"],
}


def rerun(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([rerun_executable(), *args], env=ENV, capture_output=True, text=True, timeout=120)


def verify(path: Path, footer: bool = True) -> None:
    """``path`` loads: ``rrd verify`` as it is (a footer that lists its chunks) when ``footer``, else with
    ``--check-footers false`` (a stream without one: an interrupted recording)."""
    r = rerun("rrd", "verify", str(path)) if footer else rerun("rrd", "verify", "--check-footers", "false", str(path))
    assert r.returncode == 0 and "1 file verified" in r.stdout + r.stderr, r.stdout + r.stderr


def no_footer(path: Path) -> bool:
    """``rrd verify`` as it is fails on ``path`` for want of its footer."""
    r = rerun("rrd", "verify", str(path))
    return r.returncode != 0 and "footer" in (r.stdout + r.stderr).lower()



def columns_by_entity(path: Path) -> dict[str, dict[str, int]]:
    """entity -> {column: rows} over the recording's data chunks (`rerun rrd print`)."""
    r = rerun("rrd", "print", str(path))
    assert r.returncode == 0, r.stderr
    out: dict[str, dict[str, int]] = defaultdict(lambda: defaultdict(int))
    for rows, entity, cols in CHUNK.findall(r.stdout):
        for col in cols.split():
            out[entity][col] += int(rows)
    return out


def record(path: Path, sources: dict, options: RecordOptions = RecordOptions(), duration_s: float = 1.0,
           scenario: str = "highway") -> dict:
    cfg = DriveConfig(WorldConfig(scenario, 0), duration_s, sources, default="privileged")
    holder = {}

    def factory(world):
        holder["r"] = RunRecorder(path, world.cfg.rig, world.road_geometry.lane_lines, cfg.tasks, options)
        return holder["r"]

    result = run_drive(cfg, recorder_factory=factory, render=True)
    assert holder["r"].close() == path
    verify(path)
    return result


@pytest.fixture(scope="module")
def privileged(tmp_path_factory):
    """A privileged 1 s drive's finished recording, its result and a copy of its stream as ``finish`` got it."""
    path, stream = tmp_path_factory.mktemp("priv") / "run.rrd", tmp_path_factory.mktemp("stream") / "stream.rrd"
    real_finish = recorder_module.finish

    def finish(part: Path, out: Path) -> None:
        shutil.copyfile(part, stream)
        real_finish(part, out)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(recorder_module, "finish", finish)
        result = record(path, {})
    return path, result, stream


@pytest.fixture(scope="module")
def vision(tmp_path_factory):
    path = tmp_path_factory.mktemp("vision") / "run.rrd"
    return path, record(path, {"lanes": "vision", "longitudinal": "vision"}, duration_s=2.0)


def images(cols: dict) -> int:
    return cols["/world/ego/camera/left"].get("EncodedImage:blob", 0)


def test_every_task_is_recorded_with_all_slots_privileged(privileged):
    path, result, _ = privileged
    cols = columns_by_entity(path)
    missing = [e for e in COMMON + [e for es in TASK_ENTITIES.values() for e in es] if e not in cols]
    assert not missing, f"missing entities: {missing}"
    assert not [f for f in os.listdir(path.parent) if f != path.name], "temporaries left behind"
    # one trajectory point and one ego pose per frame, never re-sent
    assert cols["/world/trajectory"]["Points3D:positions"] == result["frames"]
    assert cols["/world/ego"]["Transform3D:translation"] == result["frames"]


def test_the_drive_is_streamed_without_a_footer_and_finished_with_one_holding_the_same_data(privileged):
    """The stream has no footer (Rerun's SDK would hold its manifest, a row per chunk, in memory until the file
    closes); the finished recording is the stream compacted, with its footer."""
    path, _, stream = privileged
    assert no_footer(stream)
    verify(path)
    assert columns_by_entity(path) == columns_by_entity(stream)


def test_objects_are_under_the_ego_in_its_frame(privileged):
    cols = columns_by_entity(privileged[0])
    assert cols["/world/ego/objects"].get("Boxes3D:centers", 0) > 0
    assert not [e for e in cols if e.startswith("/world/objects")]


def test_the_vision_lanes_slot_draws_its_evidence(vision):
    cols = columns_by_entity(vision[0])
    for entity in TASK_ENTITIES["lanes"] + ["/world/ego/camera/left/lanes/evidence"]:
        assert entity in cols, entity
    # drawings on the image are stored with the image, not every frame
    assert cols["/world/ego/camera/left/lanes/boundaries"]["LineStrips2D:strips"] <= images(cols)


def test_the_vision_longitudinal_slot_records_each_cue_beside_the_fused_estimate(vision):
    cols = columns_by_entity(vision[0])
    for entity in TASK_ENTITIES["longitudinal"] + ["/longitudinal/range_m/stereo", "/longitudinal/range_m/contact",
                                                    "/longitudinal/range_rate_mps/flow",
                                                    "/world/ego/camera/left/longitudinal/lead"]:
        assert entity in cols, entity
    assert cols["/longitudinal/range_m/stereo"]["Scalars:scalars"] >= 20


@pytest.mark.slow
def test_the_vision_pedestrian_slot_draws_its_detections_and_tracks(tmp_path):
    path = tmp_path / "crossing.rrd"
    record(path, {"pedestrians": "vision"}, duration_s=4.0, scenario="crossing")
    cols = columns_by_entity(path)
    for entity in ("/world/ego/camera/left/pedestrians/detections", "/world/ego/camera/left/pedestrians/people",
                   "/world/ego/pedestrians/people"):
        assert entity in cols, entity
    # people on the image are drawn with the stored images, around the car every frame
    assert 0 < cols["/world/ego/camera/left/pedestrians/people"]["Boxes2D:half_sizes"] <= images(cols)
    assert cols["/world/ego/pedestrians/people"]["Points3D:positions"] == 60


def test_the_camera_rate_sets_how_many_images_are_stored(privileged, tmp_path):
    frames = privileged[1]["frames"]
    assert images(columns_by_entity(privileged[0])) == 5  # default 5 Hz over 1 s
    every = tmp_path / "every.rrd"
    record(every, {}, RecordOptions(camera_hz=15.0, image_scale=0.5))
    assert images(columns_by_entity(every)) == frames == 15


@pytest.mark.parametrize("kwargs, message", [
    ({"jpeg_quality": 0}, "jpeg_quality must be a whole number from 1 to 100, got 0"),
    ({"jpeg_quality": 101}, "jpeg_quality"), ({"jpeg_quality": 70.5}, "jpeg_quality"),
    ({"camera_hz": 0}, "camera_hz must be a positive number"), ({"camera_hz": float("nan")}, "camera_hz"),
    ({"image_scale": 0.0}, "image_scale must be from 0.1 to 1"), ({"image_scale": 2}, "image_scale"),
])
def test_record_options_are_validated(kwargs, message):
    with pytest.raises(ValueError, match=re.escape(message)):
        RecordOptions(**kwargs)


def test_parts_are_resolved_from_the_table(tmp_path):
    def part(rec, ctx, estimate, debug, truth):
        pass

    assert resolve_part(part) is part
    assert resolve_part("percept.review.parts.lanes:PART").plots
    for bad in ("percept.review.parts", "percept.review.parts:nothing", "no.such.module:x"):
        with pytest.raises(ValueError, match="recorder part"):
            resolve_part(bad)
    task = Task("extra", object, privileged=None, scorer=None, recorder=part)
    RunRecorder(tmp_path / "Z.rrd", StereoRig(), [], (*TASKS, task)).close()
    verify(tmp_path / "Z.rrd")
