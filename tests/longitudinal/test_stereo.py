"""`percept stereo`: dense disparity on an analytic pair and on Middlebury's motorcycle, the disparity metrics,
the two calibration formats, and every bad input (one line, exit code 2)."""

import json
from pathlib import Path

import cv2
import numpy as np
import pytest
import typer
from typer.testing import CliRunner

from percept.cli.stereo_cmd import stereo
from percept.longitudinal.dense import (DenseConfig, default_num_disparities, dense_disparity, fill_from_background,
                                        row_misalignment_px, sgbm_disparity)
from percept.longitudinal.metrics import disparity_metrics, disparity_summary
from percept.sensors import CameraCalibration, PinholeCamera
from percept.sensors.stereo_calibration import StereoCalibration
from percept.sensors.stereo_io import RectifiedStereo, read_disparity, resize_disparity

DATA = Path(__file__).resolve().parents[2] / ".." / "shared" / "data"
MOTO = DATA / "middlebury-motorcycle"
CHESS = DATA / "opencv-samples" / "stereo-chessboard"
needs_moto = pytest.mark.skipif(not MOTO.is_dir(), reason=f"{MOTO} is absent (real data in ../shared/data)")

app = typer.Typer()
app.command("stereo")(stereo)
app.command("noop")(lambda: None)  # a second command keeps typer in sub-command mode
runner = CliRunner()

H, W = 240, 320
BG_PX, FG_PX = 12.25, 23.5  # disparities of the background plane and of the raised rectangle
RECT = (60, 180, 100, 220)  # rows, cols of the rectangle in the left image: [r0, r1) x [c0, c1)


def _texture(seed: int):
    """An analytic texture: a sum of 40 plane waves, defined at every real (x, y)."""
    r = np.random.default_rng(seed)
    f, th, ph = r.uniform(0.03, 0.3, 40), r.uniform(0, np.pi, 40), r.uniform(0, 2 * np.pi, 40)

    def value(x, y):
        s = sum(np.cos(2 * np.pi * f[i] * (np.cos(th[i]) * x + np.sin(th[i]) * y) + ph[i]) for i in range(40))
        return np.clip(128 + s * 90 / np.sqrt(20), 0, 255)

    return value


def _in_rect(x, y):
    r0, r1, c0, c1 = RECT
    return (y >= r0) & (y < r1) & (x >= c0) & (x < c1)


@pytest.fixture(scope="module")
def pair():
    """(left, right, true disparity): fronto-parallel planes; the right image sees the left's point (x, y) at
    (x - d, y), so R(x, y) = texture(x + d, y) of the surface in front there."""
    bg, fg = _texture(1), _texture(2)
    y, x = np.mgrid[0:H, 0:W].astype(float)
    left = np.where(_in_rect(x, y), fg(x, y), bg(x, y))
    right = np.where(_in_rect(x + FG_PX, y), fg(x + FG_PX, y), bg(x + BG_PX, y))
    truth = np.where(_in_rect(x, y), FG_PX, BG_PX)
    return np.round(left).astype(np.uint8), np.round(right).astype(np.uint8), truth


def test_analytic_pair_is_recovered_within_a_quarter_pixel(pair):
    left, right, truth = pair
    d = dense_disparity(left, right, DenseConfig(num_disparities=48))
    peer = sgbm_disparity(left, right, 48, 3)
    r0, r1, c0, c1 = RECT
    inner = np.zeros_like(truth, bool)
    inner[r0 + 5:r1 - 5, c0 + 5:c1 - 5] = True  # the rectangle away from its edges
    far = np.ones_like(truth, bool)
    occluded = int(np.ceil(FG_PX - BG_PX))  # left of the rectangle: background the right camera cannot see
    far[r0 - 10:r1 + 10, c0 - occluded - 10:c1 + 10] = False  # the background away from the rectangle
    far[:, :int(BG_PX) + 5] = False  # columns whose partner is outside the right image
    for region in (inner, far):
        err = np.abs(d[region] - truth[region])
        assert np.isfinite(err).all() and err.max() <= 0.25
        assert np.median(err) < np.nanmedian(np.abs(peer[region] - truth[region]))  # beats SGBM's sub-pixel
    assert row_misalignment_px(left, right)[0] < 0.3


def test_disparity_metrics_on_a_hand_made_map():
    gt = np.array([[10.0, 10.0, 20.0], [np.nan, np.inf, 0.0], [5.0, 5.0, 40.0]], np.float32)
    est = np.array([[11.0, 13.0, np.nan], [3.0, 3.0, 3.0], [5.5, 5.0, 40.0]], np.float32)
    m = disparity_metrics(est, gt, focal_px=100.0, baseline_m=0.5)
    # 6 valid ground-truth pixels; errors 1, 3, (none), 0.5, 0, 0: one off by > 2 px and one without an estimate
    assert m["valid_px"] == 6
    assert m["bad_2_0_pct"] == pytest.approx(100 * 2 / 6)
    assert m["density_pct"] == pytest.approx(100 * 5 / 6)
    assert m["mae_px"] == pytest.approx((1 + 3 + 0.5 + 0 + 0) / 5)
    # Z = 50 / d: relative errors |d_gt / d - 1| = 1/11, 3/13, 1/11, 0, 0 -> median 1/11
    assert m["depth_abs_rel_err"] == pytest.approx(1 / 11, rel=1e-6)
    with_doffs = disparity_metrics(est, gt, 100.0, 0.5, doffs_px=10.0)
    # |(d_gt + 10) / (d + 10) - 1| = 1/21, 3/23, 1/31, 0, 0 -> median 1/31
    assert with_doffs["depth_abs_rel_err"] == pytest.approx(1 / 31, rel=1e-6)
    none = disparity_metrics(np.full((2, 2), np.nan), np.full((2, 2), np.nan), 100.0, 0.5)
    assert none["bad_2_0_pct"] is None and none["mae_px"] is None and none["depth_abs_rel_err"] is None
    with pytest.raises(ValueError, match="one shape"):
        disparity_metrics(est, gt[:2], 100.0, 0.5)


def test_summary_and_hole_filling():
    d = np.array([[np.nan, 4.0, np.nan, np.nan, 8.0, np.nan]], np.float32)
    assert fill_from_background(d).tolist() == [[4.0, 4.0, 4.0, 4.0, 8.0, 8.0]]  # the farther (smaller) side
    s = disparity_summary(d, 10.0 / d)
    assert s["density_pct"] == pytest.approx(100 / 3)
    assert s["disparity_px_p50"] == pytest.approx(6.0) and s["depth_m_p50"] == pytest.approx(1.875)
    assert default_num_disparities(741) == 128 and default_num_disparities(741, ndisp=70) == 80


MIDDLEBURY_CALIB = """cam0=[3979.911 0 1244.772; 0 3979.911 1019.507; 0 0 1]
cam1=[3979.911 0 1369.115; 0 3979.911 1019.507; 0 0 1]
doffs=124.343
baseline=193.001
width=2964
height=2000
ndisp=270
isint=0
"""


def test_middlebury_calib_txt_rescaled_to_the_images(tmp_path):
    (tmp_path / "calib.txt").write_text(MIDDLEBURY_CALIB)
    c = RectifiedStereo.load(tmp_path / "calib.txt")
    assert (c.fx, c.cx, c.cy, c.doffs_px, c.baseline_m) == pytest.approx((3979.911, 1244.772, 1019.507, 124.343,
                                                                          0.193001))
    assert (c.width, c.height, c.ndisp) == (2964, 2000, 270)
    q = c.for_image(741, 500)
    assert (q.fx, q.doffs_px, q.ndisp, q.width) == pytest.approx((3979.911 / 4, 124.343 / 4, 68, 741))
    # Z = f b / (d + doffs) is the same point at either scale
    assert q.depth_m(np.array([10.0]))[0] == pytest.approx(c.depth_m(np.array([40.0]))[0], rel=1e-5)
    assert np.isnan(c.depth_m(np.array([-200.0, np.nan]))).all()
    with pytest.raises(ValueError, match="aspect ratio"):
        c.for_image(741, 741)


@needs_moto
def test_shared_calib_txt_variant():
    c = RectifiedStereo.load(MOTO / "calib.txt")
    assert (c.fx, c.doffs_px, c.baseline_m, c.width) == pytest.approx((994.978, 31.086, 0.193001, None))


def _stereo_json(path: Path, baseline: float = 0.12, f: float = 500.0) -> None:
    cam = CameraCalibration(PinholeCamera(f, f, 160.0, 120.0, 320, 240), (0.0,) * 5, 0.2)
    p1 = np.array([[f, 0, 150.0, 0], [0, f, 118.0, 0], [0, 0, 1, 0]])
    p2 = np.array([[f, 0, 150.0, -f * baseline], [0, f, 118.0, 0], [0, 0, 1, 0]])
    StereoCalibration(cam, cam, np.eye(3), np.array([-baseline, 0, 0]), 0.3, 0.1, p1, p2, 10, 12).save(path)


def test_percept_stereo_calib_json(tmp_path):
    _stereo_json(tmp_path / "stereo_calib.json")
    c = RectifiedStereo.load(tmp_path / "stereo_calib.json")
    assert (c.fx, c.cx, c.cy, c.baseline_m, c.doffs_px) == pytest.approx((500.0, 150.0, 118.0, 0.12, 0.0))
    assert (c.width, c.height, c.ndisp) == (320, 240, None)
    assert c.depth_m(np.array([30.0]))[0] == pytest.approx(2.0)


@pytest.mark.parametrize("name, text, message", [
    ("calib.txt", MIDDLEBURY_CALIB.replace("baseline=193.001\n", ""), "has no baseline"),
    ("calib.txt", MIDDLEBURY_CALIB.replace("193.001", "0"), "has no baseline"),
    ("calib.json", json.dumps({"fx": 500, "fy": 500, "cx": 1, "cy": 1, "width": 9, "height": 9, "dist": []}),
     "single-camera calibration: it has no baseline|has no baseline"),
    ("calib.json", "{not json", "not valid JSON"),
    ("notes.txt", "hello world\n", "neither a Middlebury calib.txt"),
    ("calib.bin", b"\xff\xfe\x00\x81", "cannot read calibration file"),
])
def test_bad_calibrations(tmp_path, name, text, message):
    p = tmp_path / name
    p.write_bytes(text if isinstance(text, bytes) else text.encode())
    with pytest.raises(ValueError, match=message):
        RectifiedStereo.load(p)


def test_missing_calibration_and_disparity_files(tmp_path):
    with pytest.raises(ValueError, match="does not exist"):
        RectifiedStereo.load(tmp_path / "nope.txt")
    with pytest.raises(ValueError, match="does not exist"):
        read_disparity(tmp_path / "nope.npz")
    (tmp_path / "bad.npz").write_bytes(b"garbage")
    with pytest.raises(ValueError, match="cannot read disparity file"):
        read_disparity(tmp_path / "bad.npz")
    (tmp_path / "text.npy").write_text("0 1\n2 3\n")
    with pytest.raises(ValueError, match="not a NumPy .npy array"):
        read_disparity(tmp_path / "text.npy")
    np.save(tmp_path / "d.npy", np.array([[0.0, np.inf], [4.0, 2.0]]))
    d = read_disparity(tmp_path / "d.npy")
    assert np.isnan(d[0]).all() and resize_disparity(d, 4, 4)[2:, :2].tolist() == [[8.0, 8.0], [8.0, 8.0]]


def _write_pair(tmp_path: Path, left: np.ndarray, right: np.ndarray) -> list[str]:
    cv2.imwrite(str(tmp_path / "l.png"), left)
    cv2.imwrite(str(tmp_path / "r.png"), right)
    (tmp_path / "calib.txt").write_text("focal_px 500\ncx_px 160\ncy_px 120\nbaseline_mm 120\n")
    return [str(tmp_path / "l.png"), str(tmp_path / "r.png"), "--calib", str(tmp_path / "calib.txt")]


def test_cli_summary_without_ground_truth(tmp_path, pair):
    left, right, _ = pair
    args = _write_pair(tmp_path, left, right)
    r = runner.invoke(app, ["stereo", *args, "--num-disparities", "48", "--json", str(tmp_path / "s.json")])
    assert r.exit_code == 0, r.output
    s = json.loads((tmp_path / "s.json").read_text())
    assert s["scale"] == 1.0 and s["row_misalignment_px"] < 0.3 and set(s["methods"]) == {"percept", "sgbm",
                                                                                        "sgbm_sample"}
    # the background plane (most pixels) at 12.25 px: Z = 500 * 0.12 / 12.25
    assert s["disparity_px_p50"] == pytest.approx(BG_PX, abs=0.1)
    assert s["depth_m_p50"] == pytest.approx(60 / BG_PX, rel=0.01)


@pytest.mark.parametrize("case, message", [
    ("sizes", "the images differ in size"),
    ("rows", "the pair is not rectified: matched features differ by a median"),
    ("missing", "does not exist"),
    ("garbage", "cannot read"),
    ("no-baseline", "has no baseline"),
    ("gt-size", "the ground truth"),
])
def test_cli_bad_input_is_one_line_and_exit_2(tmp_path, pair, case, message, one_line_error):
    left, right, truth = pair
    right = {"sizes": right[:, :-8], "rows": np.roll(right, 4, axis=0)}.get(case, right)
    args = _write_pair(tmp_path, left, right)
    if case == "missing":
        args[1] = str(tmp_path / "absent.png")
    elif case == "garbage":
        (tmp_path / "r.png").write_bytes(b"not an image at all")
    elif case == "no-baseline":
        (tmp_path / "calib.txt").write_text("focal_px 500\ncx_px 160\ncy_px 120\n")
    elif case == "gt-size":
        np.save(tmp_path / "gt.npy", truth[:-2])
        args += ["--gt", str(tmp_path / "gt.npy")]
    out = ["--json", str(tmp_path / "o.json"), "--out", str(tmp_path / "o")]
    one_line_error(runner.invoke(app, ["stereo", *args, *out]), message)
    assert not (tmp_path / "o.json").exists() and not any((tmp_path / "o").glob("*"))  # nothing written


@pytest.mark.skipif(not CHESS.is_dir(), reason=f"{CHESS} is absent (real data in ../shared/data)")
def test_real_unrectified_pair_is_measured():
    left, right = (cv2.imread(str(CHESS / f"{s}01.jpg")) for s in ("left", "right"))
    dy, count = row_misalignment_px(left, right)
    assert count >= 20 and dy > 3.0


@needs_moto
@pytest.mark.slow
def test_middlebury_percept_is_no_worse_than_sgbm(tmp_path):
    args = [str(MOTO / "motorcycle_left.png"), str(MOTO / "motorcycle_right.png"), "--calib", str(MOTO / "calib.txt"),
            "--gt", str(MOTO / "motorcycle_disp.npz"), "--json", str(tmp_path / "m.json"), "--out", str(tmp_path)]
    r = runner.invoke(app, ["stereo", *args])
    assert r.exit_code == 0, r.output
    m = json.loads((tmp_path / "m.json").read_text())
    ours, peer = m["methods"]["percept"], m["methods"]["sgbm"]
    for v in (ours, peer):
        assert all(np.isfinite(v[k]) for k in ("bad_2_0_pct", "mae_px", "depth_abs_rel_err", "density_pct"))
    assert ours["bad_2_0_pct"] <= peer["bad_2_0_pct"]
    assert ours["depth_abs_rel_err"] <= peer["depth_abs_rel_err"]
    assert m["bad_2_0_pct"] == ours["bad_2_0_pct"] and m["row_misalignment_px"] < 0.5
    depth = np.load(tmp_path / "depth.npy")
    assert depth.dtype == np.float32 and depth.shape == (500, 741)
    assert cv2.imread(str(tmp_path / "disparity.png")).shape == (500, 741, 3)
    assert (tmp_path / "disparity_sgbm.png").is_file()
