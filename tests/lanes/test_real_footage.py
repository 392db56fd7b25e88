"""The lane module on real dash-camera footage (Udacity CarND images and video) through `percept lanes`."""

import json
from pathlib import Path

import cv2
import numpy as np
import pytest
from typer.testing import CliRunner

from percept.cli import app
from percept.lanes import marking_brightness
from percept.lanes.realworld import FootageLanes, RealLaneConfig
from percept.sensors import PinholeCamera, list_footage, open_video, read_image
from percept.sensors.chessboard import CameraCalibration, calibrate_chessboards, chessboard_images

DATA = Path(__file__).resolve().parents[2] / ".." / "shared" / "data"
LANES = DATA / "udacity-lanes"
P1 = DATA / "udacity-lanelines-p1"
VIDEO = P1 / "test_videos" / "solidWhiteRight.mp4"
needs_lanes = pytest.mark.skipif(not (LANES / "test_images").is_dir(),
                                 reason=f"{LANES} is absent (real data in ../shared/data)")
needs_p1 = pytest.mark.skipif(not (P1 / "test_images").is_dir(), reason=f"{P1} is absent (real data in ../shared/data)")
runner = CliRunner()


@pytest.fixture(scope="module")
def calib_file(tmp_path_factory):
    if not (LANES / "camera_cal").is_dir():
        pytest.skip(f"{LANES / 'camera_cal'} is absent (real data in ../shared/data)")
    path = tmp_path_factory.mktemp("cal") / "calib.json"
    calibrate_chessboards(chessboard_images(LANES / "camera_cal"), (9, 6)).save(path)
    return path


def on_marking_fraction(image: np.ndarray, points_px, half_px: int = 6, flank_px: int = 40,
                        contrast: float = 25) -> float:
    """Share of boundary points with a stripe under them: the marking brightness within +-half_px of the point
    exceeds the median of the +-flank_px row window by ``contrast`` grey levels (dashes leave gaps)."""
    m = marking_brightness(image)
    h, w = m.shape
    hits = n = 0
    for u, v in np.round(np.asarray(points_px)).astype(int):
        if flank_px <= u < w - flank_px and 0 <= v < h:
            row = m[v, u - flank_px:u + flank_px + 1]
            hits += row[flank_px - half_px:flank_px + half_px + 1].max() - np.median(row) > contrast
            n += 1
    return hits / n if n else 0.0


@needs_lanes
@pytest.mark.parametrize("calibrated", [False, True], ids=["hfov60", "calib"])
@pytest.mark.parametrize("name", ["straight_lines1.jpg", "straight_lines2.jpg"])
@pytest.mark.slow
def test_straight_lines_are_straight(name, calibrated, request):
    cal = CameraCalibration.load(request.getfixturevalue("calib_file")) if calibrated else None
    r = FootageLanes(RealLaneConfig(), cal).still(read_image(LANES / "test_images" / name))
    assert r.both_found
    assert r.debug.fit.inliers_left > 40 and r.debug.fit.inliers_right > 40
    # radius > 2 km with the camera's calibration (its lens bends straight lines), > 1 km without
    assert abs(r.estimate.curvature_1pm) < (5e-4 if calibrated else 1e-3)
    assert abs(r.estimate.heading_rad) < 0.04 and 3.0 < r.estimate.width_m < 4.3
    assert r.vanishing_point is not None and r.vanishing_point.source == "markings"


@needs_lanes
@needs_p1
@pytest.mark.parametrize("folder", [LANES / "test_images", P1 / "test_images"], ids=["udacity-lanes", "p1"])
@pytest.mark.slow
def test_every_test_image_gets_both_boundaries_on_the_markings(folder, tmp_path):
    js = tmp_path / "lanes.json"
    r = runner.invoke(app, ["lanes", str(folder), "--json", str(js), "--out", str(tmp_path)])
    assert r.exit_code == 0, r.output
    d = json.loads(js.read_text())
    files = sorted(p for p in folder.iterdir() if p.suffix == ".jpg")
    assert [Path(x["file"]).name for x in d["results"]] == [p.name for p in files]
    assert d["summary"]["both_boundaries"] == len(files)
    for res in d["results"]:
        assert res["both_boundaries"] and res["confidence"] > 0.5 and 0.0 <= res["ambiguity"] <= 0.5
        for k in ("offset_m", "heading_rad", "curvature_1pm"):
            assert isinstance(res[k], float)
        image = read_image(res["file"])
        lanes = {x["side"]: np.array(x["points_px"]) for x in res["lanes"]}
        assert set(lanes) == {"left", "right"}
        assert (lanes["left"][:, 0] < lanes["right"][:, 0]).all()
        on = sorted(on_marking_fraction(image, p) for p in lanes.values())
        # one solid line (yellow or white) is covered almost everywhere, the dashed one on its dashes
        assert on[1] > 0.8 and on[0] > 0.2, (res["file"], on)
        # and shifted by 25 px the same curves miss the paint
        assert max(on_marking_fraction(image, p + [25.0, 0.0]) for p in lanes.values()) < 0.2
        overlay = cv2.imread(str(tmp_path / (Path(res["file"]).stem + ".lanes.png")))
        assert overlay is not None and overlay.shape == image.shape


@needs_lanes
@pytest.mark.slow
def test_calibrated_images_through_the_cli(calib_file, tmp_path):
    js = tmp_path / "lanes.json"
    r = runner.invoke(app, ["lanes", str(LANES / "test_images"), "--calib", str(calib_file), "--json", str(js)])
    assert r.exit_code == 0, r.output
    d = json.loads(js.read_text())
    assert d["calibration"] == str(calib_file) and d["hfov_deg"] is None
    assert d["summary"]["both_boundaries"] == 8


@needs_lanes
@pytest.mark.slow
def test_a_runner_for_prepared_images_fits_what_the_calibrated_runner_fits(calib_file):
    raw = read_image(LANES / "test_images" / "test2.jpg")
    lanes = FootageLanes(RealLaneConfig(), CameraCalibration.load(calib_file))
    undistorted = lanes.prepare(raw)
    assert not np.array_equal(undistorted, raw)
    prepared = lanes.for_prepared()
    # the same fit from the undistorted image as from the raw one; the calibrated runner still undistorts
    assert prepared.still(undistorted).to_dict() == lanes.still(raw).to_dict()
    assert prepared.prepare(undistorted) is undistorted and lanes.prepare(raw) is not raw


@pytest.mark.skipif(not VIDEO.is_file(), reason=f"{VIDEO} is absent (real data in ../shared/data)")
@pytest.mark.slow
def test_video_runs_end_to_end(tmp_path):
    js = tmp_path / "video.json"
    r = runner.invoke(app, ["lanes", str(VIDEO), "--json", str(js), "--out", str(tmp_path), "--max-frames", "60"])
    assert r.exit_code == 0, r.output
    d = json.loads(js.read_text())
    assert d["kind"] == "video" and d["frames"] == 60 and d["fps"] == pytest.approx(25.0)
    assert [x["frame"] for x in d["results"]] == list(range(60))
    assert all(x["file"] == str(VIDEO) for x in d["results"])
    assert sum(x["both_boundaries"] for x in d["results"]) >= 57
    # one rig for the whole video, and a lane that stays put while the car keeps its lane
    assert len({x["pitch_rad"] for x in d["results"]}) == 1
    offsets = np.array([x["offset_m"] for x in d["results"]])
    assert np.abs(offsets).max() < 0.6 and np.abs(np.diff(offsets)).max() < 0.15
    cap = cv2.VideoCapture(d["overlay"])
    n = 0
    while cap.read()[0]:
        n += 1
    assert n == 60


def test_library_bad_input(tmp_path):
    with pytest.raises(ValueError, match="holds no images"):
        list_footage(tmp_path)
    with pytest.raises(ValueError, match="does not exist"):
        list_footage(tmp_path / "nothing.jpg")
    (tmp_path / "broken.jpg").write_text("not a jpeg")
    (tmp_path / "broken.mp4").write_text("not a video")
    with pytest.raises(ValueError, match="cannot read .* as an image"):
        read_image(tmp_path / "broken.jpg")
    with pytest.raises(ValueError, match="cannot read .* as a video"):
        open_video(tmp_path / "broken.mp4")
    with pytest.raises(ValueError, match="mount height"):
        RealLaneConfig(mount_height_m=-1.0)
    cal = CameraCalibration(PinholeCamera(1000.0, 1000.0, 640.0, 360.0, 1280, 720), (0.0,) * 5, 0.5)
    with pytest.raises(ValueError, match="calibration is for 1280x720"):
        FootageLanes(RealLaneConfig(), cal).still(np.zeros((540, 960, 3), np.uint8))


def test_a_blank_image_finds_no_lane_without_failing(tmp_path):
    r = FootageLanes().still(np.full((540, 960, 3), 90, np.uint8))
    assert not r.estimate.valid and r.boundaries_px == {}
    cv2.imwrite(str(tmp_path / "grey.png"), np.full((540, 960, 3), 90, np.uint8))
    js = tmp_path / "g.json"
    res = runner.invoke(app, ["lanes", str(tmp_path / "grey.png"), "--json", str(js)])
    assert res.exit_code == 0, res.output
    g = json.loads(js.read_text())["results"][0]
    assert g["lanes"] == [] and g["offset_m"] is None and g["confidence"] == 0.0


def test_cli_bad_input(tmp_path, one_line_error):
    (tmp_path / "broken.jpg").write_text("not a jpeg")
    (tmp_path / "broken.mp4").write_text("not a video")
    (tmp_path / "notes.txt").write_text("hello")
    empty = tmp_path / "empty"
    empty.mkdir()
    one_line_error(runner.invoke(app, ["lanes", str(tmp_path / "broken.jpg")]), "cannot read")
    one_line_error(runner.invoke(app, ["lanes", str(tmp_path / "broken.mp4")]), "as a video")
    one_line_error(runner.invoke(app, ["lanes", str(empty)]), "holds no images")
    one_line_error(runner.invoke(app, ["lanes", str(tmp_path / "missing.png")]), "does not exist")
    one_line_error(runner.invoke(app, ["lanes", str(tmp_path / "notes.txt")]), "neither an image")
    one_line_error(runner.invoke(app, ["lanes", str(tmp_path / "broken.jpg"), "--calib", str(tmp_path / "notes.txt")]),
                    "not a percept calibration file")
    one_line_error(runner.invoke(app, ["lanes", str(empty), "--mount-height", "0"]),
                    "--mount-height must be a finite number")
    one_line_error(runner.invoke(app, ["lanes", str(tmp_path / "broken.mp4"), "--max-frames", "0"]), "--max-frames")


@needs_p1
def test_a_folder_with_one_unreadable_image_keeps_the_others(tmp_path, calib_file, one_line_error):
    src = P1 / "test_images" / "solidWhiteRight.jpg"
    (tmp_path / "a.jpg").write_bytes(src.read_bytes())
    (tmp_path / "b.jpg").write_text("broken")
    js = tmp_path / "r.json"
    r = runner.invoke(app, ["lanes", str(tmp_path), "--json", str(js)])
    assert r.exit_code == 0, r.output
    assert "skipped" in r.output
    d = json.loads(js.read_text())
    assert d["summary"] == {**d["summary"], "count": 1, "errors": 1, "both_boundaries": 1}
    # a 960x540 image with a 1280x720 calibration: one line, exit 2
    one_line_error(runner.invoke(app, ["lanes", str(src), "--calib", str(calib_file)]), "calibration is for 1280x720")


def test_truncated_footage_through_the_cli(tmp_path, one_line_error):
    """A cut JPEG is one clear error; a cut video keeps the frames it has and says it ended early."""
    grey = np.full((240, 320, 3), 90, np.uint8)
    cv2.imwrite(str(tmp_path / "a.jpg"), grey)
    data = (tmp_path / "a.jpg").read_bytes()
    (tmp_path / "cut.jpg").write_bytes(data[:len(data) // 2])
    one_line_error(runner.invoke(app, ["lanes", str(tmp_path / "cut.jpg")]), "truncated")
    w = cv2.VideoWriter(str(tmp_path / "v.avi"), cv2.VideoWriter_fourcc(*"MJPG"), 10.0, (320, 240))
    for _ in range(30):
        w.write(grey)
    w.release()
    data = (tmp_path / "v.avi").read_bytes()
    (tmp_path / "cut.avi").write_bytes(data[:len(data) // 2])
    js = tmp_path / "cut.json"
    r = runner.invoke(app, ["lanes", str(tmp_path / "cut.avi"), "--json", str(js)])
    assert r.exit_code == 0, r.output
    assert "ended after" in r.output
    d = json.loads(js.read_text())
    assert d["ended_early"] and d["frames_declared"] == 30 and 0 < d["frames"] < 30
