"""Camera calibration from chessboards (library and `percept calibrate`)."""

import json
import math
import shutil
from pathlib import Path

import cv2
import numpy as np
import pytest
from typer.testing import CliRunner

from percept.cli import app
from percept.sensors import PinholeCamera
from percept.sensors.chessboard import CameraCalibration, calibrate_chessboards, chessboard_images, parse_pattern

DATA = Path(__file__).resolve().parents[2] / ".." / "shared" / "data"
CAL_DIR = DATA / "udacity-lanes" / "camera_cal"
needs_cal = pytest.mark.skipif(not CAL_DIR.is_dir(), reason=f"{CAL_DIR} is absent (real data in ../shared/data)")
runner = CliRunner()


@pytest.mark.parametrize("text, expected", [("9x6", (9, 6)), (" 7X5 ", (7, 5)), ("4×3", (4, 3))])
def test_pattern_strings(text, expected):
    assert parse_pattern(text) == expected


@pytest.mark.parametrize("text, match", [("9by6", "not COLSxROWS"), ("9x", "not COLSxROWS"), ("1x6", "at least 3x3"),
                                         ("2x2", "at least 3x3"),
                                         ("99999999999x2", "more than 100 inner corners")])
def test_bad_pattern_strings(text, match):
    with pytest.raises(ValueError, match=match):
        parse_pattern(text)


def test_synthetic_board_recovers_the_focal_length(tmp_path):
    """A rendered 9x6 board seen from 8 poses by a known camera: calibration finds f within 1 %."""
    cam = PinholeCamera.from_hfov(640, 480, math.radians(60))
    sq = 40  # px per square in the board texture
    board = np.full((7 * sq + 2 * sq, 10 * sq + 2 * sq), 255, np.uint8)
    for r in range(7):
        for c in range(10):
            if (r + c) % 2 == 0:
                board[sq + r * sq:sq + (r + 1) * sq, sq + c * sq:sq + (c + 1) * sq] = 0
    rng = np.random.default_rng(0)
    paths = []
    for i in range(8):
        rvec = rng.uniform(-0.35, 0.35, 3)
        R, _ = cv2.Rodrigues(rvec)
        t = np.array([0.0, 0.0, 1.6]) + rng.uniform(-0.1, 0.1, 3)
        # board plane points (metres, 1 square = 0.05 m), centred: texture pixel -> board -> camera -> image
        s = 0.05 / sq
        T = np.array([[s, 0, -board.shape[1] * s / 2], [0, s, -board.shape[0] * s / 2], [0, 0, 1]])
        H = cam.K @ np.column_stack([R[:, 0], R[:, 1], t]) @ T
        img = cv2.warpPerspective(board, H, (640, 480), borderValue=128)
        paths.append(tmp_path / f"b{i}.png")
        cv2.imwrite(str(paths[-1]), img)
    cal = calibrate_chessboards(paths, (9, 6))
    assert cal.images_used == 8 and cal.rms_px < 0.5
    assert cal.camera.fx == pytest.approx(cam.fx, rel=0.01) and cal.camera.fy == pytest.approx(cam.fy, rel=0.01)


def test_calibration_file_round_trip_and_bad_files(tmp_path):
    cam = PinholeCamera(1000.0, 1001.0, 640.0, 360.0, 1280, 720)
    cal = CameraCalibration(cam, (-0.2, 0.05, 0.0, 0.0, 0.0), 0.5, 10, 12, 15)
    cal.save(tmp_path / "c.json")
    assert CameraCalibration.load(tmp_path / "c.json") == cal
    assert [p.name for p in tmp_path.iterdir()] == ["c.json"]  # written under a temporary name, then renamed
    # the file stays flat: the fields of the camera beside the distortion and the counts
    assert json.loads((tmp_path / "c.json").read_text()) == {
        "fx": 1000.0, "fy": 1001.0, "cx": 640.0, "cy": 360.0, "width": 1280, "height": 720,
        "dist": [-0.2, 0.05, 0.0, 0.0, 0.0], "rms_px": 0.5, "images_used": 10, "images_found": 12,
        "images_total": 15, "pattern": "9x6"}
    assert cal.K[0, 0] == 1000.0 and cal.camera is cam
    with pytest.raises(ValueError, match="does not exist"):
        CameraCalibration.load(tmp_path / "missing.json")
    (tmp_path / "bad.json").write_text('{"fx": 1}')
    with pytest.raises(ValueError, match="not a percept calibration file"):
        CameraCalibration.load(tmp_path / "bad.json")
    with pytest.raises(ValueError, match="calibration is for 1280x720"):
        cal.undistort(np.zeros((540, 960, 3), np.uint8))
    (tmp_path / "nan.json").write_text(json.dumps({**cal.to_dict(), "dist": [0.1, "nan", 0, 0, 0]}))
    with pytest.raises(ValueError, match="not a percept calibration file.*finite"):
        CameraCalibration.load(tmp_path / "nan.json")
    with pytest.raises(ValueError, match="is a folder"):
        CameraCalibration.load(tmp_path)
    (tmp_path / "rig.json").write_text(json.dumps({"left": cal.to_dict(), "right": cal.to_dict(), "baseline_m": 0.5}))
    with pytest.raises(ValueError, match="calibrates a stereo rig; give one camera's"):
        CameraCalibration.load(tmp_path / "rig.json")


def test_no_board_and_no_images(tmp_path):
    with pytest.raises(ValueError, match="holds no images"):
        chessboard_images(tmp_path)
    cv2.imwrite(str(tmp_path / "grey.png"), np.full((120, 160), 128, np.uint8))
    with pytest.raises(ValueError, match="no 9x6 chessboard found in any of 1 photos"):
        calibrate_chessboards(chessboard_images(tmp_path), (9, 6))


def test_one_or_two_views_are_refused(tmp_path):
    """A single front-on board leaves the focal length undetermined (it came out near 1e18 px): refused."""
    board = np.full((9 * 40, 12 * 40), 255, np.uint8)
    for r in range(7):
        for c in range(10):
            if (r + c) % 2 == 0:
                board[40 + r * 40:80 + r * 40, 40 + c * 40:80 + c * 40] = 0
    for k in range(2):
        cv2.imwrite(str(tmp_path / f"b{k}.png"), board)
    with pytest.raises(ValueError, match="found in only 2 photo"):
        calibrate_chessboards(chessboard_images(tmp_path), (9, 6))


@needs_cal
@pytest.mark.slow
def test_percept_calibrate_on_the_udacity_photos(tmp_path):
    out, js = tmp_path / "calib.json", tmp_path / "report.json"
    r = runner.invoke(app, ["calibrate", str(CAL_DIR), "--pattern", "9x6", "--out", str(out), "--json", str(js)])
    assert r.exit_code == 0, r.output
    assert "RMS reprojection error" in r.output and "17 of 20" in r.output
    d = json.loads(out.read_text())
    for k in ("fx", "fy", "cx", "cy", "width", "height", "dist", "rms_px"):
        assert k in d
    assert d["rms_px"] < 1.0 and (d["width"], d["height"]) == (1280, 720)
    assert 1000 < d["fx"] < 1300 and len(d["dist"]) == 5
    assert json.loads(js.read_text())["rms_px"] == d["rms_px"]
    # the file is what `percept lanes --calib` reads
    cal = CameraCalibration.load(out)
    assert cal.images_used == 15 and cal.images_found == 17 and cal.images_total == 20


@needs_cal
def test_percept_calibrate_default_output_and_partial_boards(tmp_path):
    # calibration1.jpg does not show the whole board; the other photos do
    for name in ("calibration1.jpg", "calibration2.jpg", "calibration3.jpg", "calibration6.jpg"):
        shutil.copy(CAL_DIR / name, tmp_path / name)
    r = runner.invoke(app, ["calibrate", str(tmp_path)])
    assert r.exit_code == 0, r.output
    assert "3 of 4" in r.output
    assert json.loads((tmp_path / "calib.json").read_text())["images_used"] == 3


@needs_cal
def test_percept_calibrate_bad_input(tmp_path, one_line_error):
    one_line_error(runner.invoke(app, ["calibrate", str(CAL_DIR), "--pattern", "9by6"]))
    one_line_error(runner.invoke(app, ["calibrate", str(tmp_path / "missing")]))
    empty = tmp_path / "empty"
    empty.mkdir()
    one_line_error(runner.invoke(app, ["calibrate", str(empty)]))
    noboard = tmp_path / "noboard"
    noboard.mkdir()
    shutil.copy(CAL_DIR / "calibration1.jpg", noboard)
    r = runner.invoke(app, ["calibrate", str(noboard), "--pattern", "9x6"])
    one_line_error(r)
    assert "no 9x6 chessboard found" in r.output
    assert not (noboard / "calib.json").exists()
