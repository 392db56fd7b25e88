"""`percept detect` on images, folders and video: the JSON and the overlays; bad input is one line and exit 2."""

import json
from pathlib import Path

import cv2
import numpy as np
import pytest
from typer.testing import CliRunner

from percept.cli import app

runner = CliRunner()
VTEST = Path(__file__).resolve().parents[2] / ".." / "shared" / "data" / "opencv-samples" / "pedestrians" / "vtest.avi"
needs_vtest = pytest.mark.skipif(not VTEST.is_file(), reason=f"{VTEST} is absent (real data in ../shared/data)")



@pytest.fixture(scope="module")
def frame(tmp_path_factory):
    if not VTEST.is_file():
        pytest.skip(f"{VTEST} is absent (real data in ../shared/data)")
    cap = cv2.VideoCapture(str(VTEST))
    ok, img = cap.read()
    path = tmp_path_factory.mktemp("frames") / "street.png"
    cv2.imwrite(str(path), img)
    return path


@needs_vtest
def test_detect_on_an_image_writes_its_detections_and_an_overlay(frame, tmp_path):
    r = runner.invoke(app, ["detect", str(frame), "--json", str(tmp_path / "d.json"), "--out", str(tmp_path / "o")])
    assert r.exit_code == 0, r.output
    d = json.loads((tmp_path / "d.json").read_text())
    assert d["model"] == "inria" and d["kind"] == "images"
    dets = d["results"][0]["detections"]
    assert d["results"][0]["file"] == str(frame) and len(dets) >= 2
    for det in dets:
        u0, v0, u1, v1 = det["box_px"]
        assert u1 - u0 >= 64 and v1 - v0 >= 128 and isinstance(det["score"], float)
    assert cv2.imread(str(tmp_path / "o" / "street.detect.png")).shape == (576, 768, 3)


@needs_vtest
def test_detect_on_a_video_writes_every_frame_and_an_overlay_video(tmp_path):
    r = runner.invoke(app, ["detect", str(VTEST), "--max-frames", "3", "--json", str(tmp_path / "v.json"),
                            "--out", str(tmp_path)])
    assert r.exit_code == 0, r.output
    d = json.loads((tmp_path / "v.json").read_text())
    assert [x["frame"] for x in d["results"]] == [0, 1, 2] and d["kind"] == "video"
    cap = cv2.VideoCapture(str(tmp_path / "vtest.detect.mp4"))
    assert int(cap.get(cv2.CAP_PROP_FRAME_COUNT)) == 3


def test_bad_input_is_one_line_and_exit_2(tmp_path, one_line_error):
    one_line_error(runner.invoke(app, ["detect", str(tmp_path / "none.png")]), "does not exist")
    (tmp_path / "broken.png").write_bytes(b"\x89PNG\r\n\x1a\n not really")
    one_line_error(runner.invoke(app, ["detect", str(tmp_path / "broken.png")]), "broken.png")
    cv2.imwrite(str(tmp_path / "small.png"), np.zeros((100, 50, 3), np.uint8))
    one_line_error(runner.invoke(app, ["detect", str(tmp_path / "small.png")]), "smaller than the 64x128")
    cv2.imwrite(str(tmp_path / "ok.png"), np.zeros((200, 100, 3), np.uint8))
    one_line_error(runner.invoke(app, ["detect", str(tmp_path / "ok.png"), "--model", str(tmp_path / "m.npz")]),
                   "does not exist")
    (tmp_path / "m.npz").write_bytes(b"corrupt")
    one_line_error(runner.invoke(app, ["detect", str(tmp_path / "ok.png"), "--model", str(tmp_path / "m.npz")]),
                   "is not a percept HOG model")
    one_line_error(runner.invoke(app, ["detect", str(tmp_path / "ok.png"), "--scale-step", "1"]), "--scale-step")
    (tmp_path / "clip.avi").write_bytes(b"RIFF0000AVI junk")
    one_line_error(runner.invoke(app, ["detect", str(tmp_path / "clip.avi")]), "clip.avi")
    assert not (tmp_path / "d.json").exists()


def test_a_folder_skips_what_it_cannot_read_and_keeps_the_rest(tmp_path):
    cv2.imwrite(str(tmp_path / "a.png"), np.full((160, 96, 3), 120, np.uint8))
    (tmp_path / "b.png").write_bytes(b"junk")
    r = runner.invoke(app, ["detect", str(tmp_path), "--json", str(tmp_path / "out.json")])
    assert r.exit_code == 0, r.output
    d = json.loads((tmp_path / "out.json").read_text())
    assert d["summary"]["count"] == 1 and d["summary"]["errors"] == 1
    assert d["results"][0]["detections"] == []
