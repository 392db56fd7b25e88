"""Bad input files and option values of the footage commands: one line, exit code 2, nothing written; a folder's
unreadable image or an unpaired stereo photo is left out with a warning line naming it."""

import json
import shutil
from pathlib import Path

import cv2
import numpy as np
import pytest
from typer.testing import CliRunner

from percept.cli import app
from percept.sensors import read_image
from percept.sensors.stereo_io import read_disparity

runner = CliRunner()
PAIRS = Path(__file__).resolve().parents[2] / ".." / "shared" / "data" / "opencv-samples" / "stereo-chessboard"
needs_pairs = pytest.mark.skipif(not PAIRS.is_dir(), reason=f"{PAIRS} is absent (real data in ../shared/data)")


def _texture(h: int, w: int, seed: int = 0) -> np.ndarray:
    """A smooth random texture (H, W, 3) uint8 that feature matching and block matching can lock on."""
    noise = np.random.default_rng(seed).integers(0, 255, (h, w), dtype=np.uint8)
    return cv2.cvtColor(cv2.GaussianBlur(noise, (0, 0), 1.5), cv2.COLOR_GRAY2BGR)


def _bad_files(tmp_path: Path) -> dict[str, Path]:
    """An empty PNG, an empty JPEG, a PNG and a JPEG cut in half, and a text file named .png."""
    img = _texture(64, 96)
    cv2.imwrite(str(tmp_path / "whole.png"), img)
    cv2.imwrite(str(tmp_path / "whole.jpg"), img)
    files = {"empty.png": b"", "empty.jpg": b"", "junk.png": b"not an image at all"}
    for name in ("whole.png", "whole.jpg"):
        data = (tmp_path / name).read_bytes()
        files["cut" + name[5:]] = data[:len(data) // 2]
    for name, data in files.items():
        (tmp_path / name).write_bytes(data)
    return {name: tmp_path / name for name in files}


@pytest.mark.parametrize("name, message", [("empty.png", "the file is empty (0 bytes)"),
                                           ("empty.jpg", "the file is empty (0 bytes)"),
                                           ("cut.png", "truncated (no PNG IEND chunk)"),
                                           ("cut.jpg", "truncated (no JPEG end-of-image marker FFD9)"),
                                           ("junk.png", "not an image file")])
def test_read_image_refuses_what_opencv_cannot_decode(tmp_path, name, message):
    path = _bad_files(tmp_path)[name]
    for gray in (False, True):
        with pytest.raises(ValueError, match="cannot read .* as an image") as e:
            read_image(path, gray=gray)
        assert str(path) in str(e.value) and message in str(e.value)


def test_an_empty_pfm_disparity_is_a_value_error(tmp_path):
    (tmp_path / "d.pfm").write_bytes(b"")
    with pytest.raises(ValueError, match="cannot read disparity file .*d.pfm"):
        read_disparity(tmp_path / "d.pfm")


@pytest.mark.parametrize("command", ["lanes", "detect"])
@pytest.mark.parametrize("name", ["empty.png", "empty.jpg", "cut.jpg", "junk.png"])
def test_a_single_bad_image_is_one_line(tmp_path, one_line_error, command, name):
    path = _bad_files(tmp_path)[name]
    js = tmp_path / "out.json"
    one_line_error(runner.invoke(app, [command, str(path), "--json", str(js)]), f"cannot read {path}")
    assert not js.exists()


@pytest.mark.parametrize("command", ["lanes", "detect"])
def test_a_folder_with_one_empty_image_skips_it_with_a_warning(tmp_path, command):
    folder = tmp_path / "shots"
    folder.mkdir()
    cv2.imwrite(str(folder / "a.png"), _texture(160, 96))
    (folder / "b.png").write_bytes(b"")
    js = tmp_path / "out.json"
    r = runner.invoke(app, [command, str(folder), "--json", str(js)])
    assert r.exit_code == 0, r.output
    assert "Traceback" not in r.output and "error:" not in r.output
    assert f"cannot read {folder / 'b.png'} as an image: the file is empty" in r.output
    d = json.loads(js.read_text())
    assert d["summary"]["count"] == 1 and d["summary"]["errors"] == 1
    assert [r["file"] for r in d["results"] if "error" in r] == [str(folder / "b.png")]


@pytest.mark.parametrize("command", ["lanes", "detect"])
def test_a_folder_of_only_empty_images_is_one_line(tmp_path, one_line_error, command):
    (tmp_path / "a.png").write_bytes(b"")
    (tmp_path / "b.jpg").write_bytes(b"")
    js = tmp_path / "out.json"
    one_line_error(runner.invoke(app, [command, str(tmp_path), "--json", str(js)]), "none of the 2 images")
    assert not js.exists()


def _pair(tmp_path: Path, h: int = 64, w: int = 100, calib: str = "") -> list[str]:
    """A rectified pair (the right image is the left one shifted 4 px) and its calib.txt; the command's arguments."""
    left = _texture(h, w + 4)
    cv2.imwrite(str(tmp_path / "l.png"), left[:, 4:])
    cv2.imwrite(str(tmp_path / "r.png"), left[:, :-4])
    (tmp_path / "calib.txt").write_text(f"focal_px 500\ncx_px {w / 2}\ncy_px {h / 2}\nbaseline_mm 120\n{calib}")
    return [str(tmp_path / "l.png"), str(tmp_path / "r.png"), "--calib", str(tmp_path / "calib.txt")]


@pytest.mark.parametrize("name, message", [("empty.png", "the file is empty"), ("cut.png", "truncated"),
                                           ("cut.jpg", "truncated"), ("junk.png", "not an image file")])
@pytest.mark.parametrize("side", [0, 1])
def test_stereo_refuses_a_bad_image_in_one_line(tmp_path, one_line_error, name, message, side):
    args = _pair(tmp_path)
    args[side] = str(_bad_files(tmp_path)[name])
    out = ["--json", str(tmp_path / "o.json"), "--out", str(tmp_path / "o")]
    one_line_error(runner.invoke(app, ["stereo", *args, *out]), f"cannot read {args[side]} as an image")
    assert message in runner.invoke(app, ["stereo", *args]).output
    assert not (tmp_path / "o.json").exists() and not any((tmp_path / "o").glob("*"))


@pytest.mark.parametrize("value, message", [
    ("0", "--num-disparities must be a multiple of 16 from 16 to 1024, got 0"),
    ("17", "--num-disparities must be a multiple of 16 from 16 to 1024, got 17"),
    ("2048", "--num-disparities must be a multiple of 16 from 16 to 1024, got 2048"),
    # 100 px wide with a 3 px block: n + 1 < 100 allows at most 96
    ("112", "--num-disparities must be a multiple of 16 from 16 to 96 for these 100x64 px images at scale 1 "
            "with --block-size 3, got 112"),
    ("1024", "from 16 to 96 for these 100x64 px images"),
])
def test_stereo_num_disparities_is_checked_against_the_image_width(tmp_path, one_line_error, value, message):
    args = _pair(tmp_path)
    js = tmp_path / "o.json"
    one_line_error(runner.invoke(app, ["stereo", *args, "--num-disparities", value, "--json", str(js)]), message)
    assert not js.exists()


def test_stereo_num_disparities_up_to_the_bound_runs(tmp_path):
    args = _pair(tmp_path)
    js = tmp_path / "o.json"
    r = runner.invoke(app, ["stereo", *args, "--num-disparities", "96", "--json", str(js)])
    assert r.exit_code == 0, r.output
    assert json.loads(js.read_text())["num_disparities"] == 96
    # a wider block takes columns: 100 px with an 11 px block allows at most 80
    r = runner.invoke(app, ["stereo", *args, "--num-disparities", "96", "--block-size", "11"])
    assert r.exit_code == 2 and "from 16 to 80" in r.output


def test_stereo_default_range_stays_within_the_width(tmp_path):
    """A calibration's ndisp wider than the image is cut to what the width allows."""
    args = _pair(tmp_path, calib="ndisp 290\n")
    js = tmp_path / "o.json"
    r = runner.invoke(app, ["stereo", *args, "--json", str(js)])
    assert r.exit_code == 0, r.output
    assert json.loads(js.read_text())["num_disparities"] == 96


def test_stereo_help_states_the_range():
    r = runner.invoke(app, ["stereo", "--help"], env={"COLUMNS": "200"})
    text = " ".join(r.output.split())
    assert "multiple of 16 from 16 to 1024" in text and "below the working width" in text


def _copy_pairs(tmp_path: Path, numbers: list[str]) -> Path:
    """A folder holding left<N>.jpg and right<N>.jpg of the sample rig for each N in ``numbers``."""
    folder = tmp_path / "rig"
    folder.mkdir()
    for n in numbers:
        for side in ("left", "right"):
            shutil.copy(PAIRS / f"{side}{n}.jpg", folder / f"{side}{n}.jpg")
    return folder


@needs_pairs
def test_calibrate_stereo_warns_about_an_unpaired_photo(tmp_path):
    folder = _copy_pairs(tmp_path, ["01", "02", "03", "04"])
    shutil.copy(PAIRS / "left05.jpg", folder / "left05.jpg")
    shutil.copy(PAIRS / "right06.jpg", folder / "right06.jpg")
    out = tmp_path / "rig.json"
    r = runner.invoke(app, ["calibrate", str(folder), "--stereo", "--out", str(out)])
    assert r.exit_code == 0, r.output
    lines = r.output.splitlines()
    left05 = f"warning: {folder / 'left05.jpg'} has no partner right05.jpg; it is left out"
    right06 = f"warning: {folder / 'right06.jpg'} has no partner left06.jpg; it is left out"
    assert left05 in lines and right06 in lines
    assert lines.index(left05) < min(i for i, line in enumerate(lines) if "stereo rig calibration" in line)
    assert json.loads(out.read_text())["pairs_total"] == 4


@needs_pairs
def test_calibrate_stereo_warns_about_an_empty_photo_and_calibrates_without_its_pair(tmp_path):
    folder = _copy_pairs(tmp_path, ["01", "02", "03", "04"])
    (folder / "right04.jpg").write_bytes(b"")
    r = runner.invoke(app, ["calibrate", str(folder), "--stereo", "--out", str(tmp_path / "rig.json")])
    assert r.exit_code == 0, r.output
    assert (f"warning: cannot read {folder / 'right04.jpg'} as an image: the file is empty (0 bytes); copy it "
            "again; its pair is left out") in r.output.splitlines()
    d = json.loads((tmp_path / "rig.json").read_text())
    assert d["pairs_used"] == 3 and d["pairs_total"] == 4


@needs_pairs
def test_calibrate_one_camera_warns_about_an_empty_photo(tmp_path):
    folder = tmp_path / "cam"
    folder.mkdir()
    for n in ("01", "02", "03", "04"):
        shutil.copy(PAIRS / f"left{n}.jpg", folder / f"left{n}.jpg")
    (folder / "left05.jpg").write_bytes(b"")
    r = runner.invoke(app, ["calibrate", str(folder), "--out", str(tmp_path / "calib.json")])
    assert r.exit_code == 0, r.output
    assert (f"warning: cannot read {folder / 'left05.jpg'} as an image: the file is empty (0 bytes); copy it "
            "again; the photo is left out") in r.output.splitlines()
    assert json.loads((tmp_path / "calib.json").read_text())["images_used"] == 4


def test_calibrate_a_folder_of_empty_photos_is_one_line(tmp_path, one_line_error):
    for name in ("left01.jpg", "right01.jpg"):
        (tmp_path / name).write_bytes(b"")
    for extra in ([], ["--stereo"]):
        out = tmp_path / "c.json"
        r = runner.invoke(app, ["calibrate", str(tmp_path), *extra, "--out", str(out)])
        one_line_error(r, "none of the photos could be read" if not extra else "board was found in both images "
                                                                                 "of only 0 of 1 pairs")
        assert not out.exists()


def test_calibrate_stereo_without_any_pair_is_one_line(tmp_path, one_line_error):
    cv2.imwrite(str(tmp_path / "left01.png"), np.zeros((48, 64), np.uint8))
    one_line_error(runner.invoke(app, ["calibrate", str(tmp_path), "--stereo"]), "holds no stereo pairs")
