"""Stereo rig calibration from chessboard pairs: a synthetic rig with a known baseline, OpenCV's sample pairs,
`percept calibrate --stereo` and its bad input."""

import json
import math
from pathlib import Path

import cv2
import numpy as np
import pytest
from typer.testing import CliRunner

from percept.cli import app
from percept.sensors import PinholeCamera
from percept.sensors.stereo_calibration import calibrate_stereo, stereo_pairs

DATA = Path(__file__).resolve().parents[2] / ".." / "shared" / "data" / "opencv-samples" / "stereo-chessboard"
needs_pairs = pytest.mark.skipif(not DATA.is_dir(), reason=f"{DATA} is absent (real data in ../shared/data)")
runner = CliRunner()


def _board(sq: int = 40) -> np.ndarray:
    """A 10x7-square board (9x6 inner corners) with a one-square white margin, sq px per square."""
    board = np.full((9 * sq, 12 * sq), 255, np.uint8)
    for r in range(7):
        for c in range(10):
            if (r + c) % 2 == 0:
                board[sq + r * sq:sq + (r + 1) * sq, sq + c * sq:sq + (c + 1) * sq] = 0
    return board


def test_synthetic_rig_gives_back_its_baseline(tmp_path):
    """Two identical cameras 0.30 m apart (right camera at +x in the left one's frame), a board of 5 cm squares
    in 12 poses: the calibrated baseline is 0.30 m within 1 % and T points along -x (x_r = R x_l + T)."""
    cam = PinholeCamera.from_hfov(640, 480, math.radians(60))
    board, sq = _board(), 40
    s = 0.05 / sq
    # texture pixel -> board plane (metres, centred)
    T_tex = np.array([[s, 0, -board.shape[1] * s / 2], [0, s, -board.shape[0] * s / 2], [0, 0, 1]])
    rng = np.random.default_rng(1)
    for i in range(12):
        R, _ = cv2.Rodrigues(rng.uniform(-0.4, 0.4, 3))
        t = np.array([0.15, 0.0, 1.5]) + rng.uniform(-0.1, 0.1, 3)
        for side, dx in (("left", 0.0), ("right", -0.30)):
            # the right camera sees the board shifted by -B along x
            H = cam.K @ np.column_stack([R[:, 0], R[:, 1], t + np.array([dx, 0, 0])]) @ T_tex
            cv2.imwrite(str(tmp_path / f"{side}{i:02d}.png"), cv2.warpPerspective(board, H, (640, 480),
                                                                                  borderValue=128))
    cal = calibrate_stereo(stereo_pairs(tmp_path), (9, 6), square_m=0.05)
    assert cal.pairs_used == 12 and cal.rms_px < 0.5 and cal.epipolar_px < 0.3
    assert cal.baseline_m == pytest.approx(0.30, rel=0.01)
    assert cal.T[0] == pytest.approx(-0.30, rel=0.01)
    assert np.allclose(cal.R, np.eye(3), atol=0.01)
    assert cal.left.camera.fx == pytest.approx(cam.fx, rel=0.01)


@needs_pairs
def test_opencv_sample_pairs_calibrate_with_sub_pixel_error():
    cal = calibrate_stereo(stereo_pairs(DATA), (9, 6))
    assert cal.pairs_used == cal.pairs_total == 13
    assert cal.rms_px < 1.0 and cal.epipolar_px < 0.5
    # a side-by-side rig: the translation is nearly all along x
    assert abs(cal.T[0]) > 0.98 * cal.baseline_m


@needs_pairs
def test_percept_calibrate_stereo_writes_the_rig(tmp_path):
    out = tmp_path / "rig.json"
    r = runner.invoke(app, ["calibrate", str(DATA), "--stereo", "--square", "0.025", "--out", str(out),
                            "--json", str(tmp_path / "figures.json")])
    assert r.exit_code == 0, r.output
    d = json.loads(out.read_text())
    assert set(d) >= {"left", "right", "R", "T", "baseline_m", "rms_px", "epipolar_px", "P1", "P2"}
    assert np.array(d["R"]).shape == (3, 3) and np.array(d["P2"]).shape == (3, 4)
    assert d["baseline_m"] == pytest.approx(np.linalg.norm(d["T"]))
    assert json.loads((tmp_path / "figures.json").read_text())["rms_px"] == d["rms_px"]


def test_percept_calibrate_stereo_bad_input(tmp_path, one_line_error):
    cv2.imwrite(str(tmp_path / "a.png"), np.zeros((48, 64), np.uint8))
    one_line_error(runner.invoke(app, ["calibrate", str(tmp_path), "--stereo"]), "no stereo pairs")
    for k in range(3):
        cv2.imwrite(str(tmp_path / f"left{k}.png"), np.zeros((48, 64), np.uint8))
        cv2.imwrite(str(tmp_path / f"right{k}.png"), np.zeros((48, 64), np.uint8))
    one_line_error(runner.invoke(app, ["calibrate", str(tmp_path), "--stereo"]),
                   "found in both images of only 0 of 3 pairs")
    one_line_error(runner.invoke(app, ["calibrate", str(tmp_path), "--stereo", "--square", "0"]),
                   "--square must be a finite number")
    assert not (tmp_path / "stereo_calib.json").exists()
