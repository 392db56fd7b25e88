"""KITTI-layout folders: the real sequence, both naming schemes, and one clear error per kind of bad input."""

from pathlib import Path

import cv2
import numpy as np
import pytest

from percept.odometry import load_kitti_folder

KITTI = Path(__file__).resolve().parents[2] / ".." / "shared" / "data" / "kitti-odometry-seq"
P0 = "700 0 320 0 0 700 240 0 0 0 1 0"
P1 = "700 0 320 -378 0 700 240 0 0 0 1 0"  # baseline 378 / 700 = 0.54 m
POSE = "1 0 0 0 0 1 0 0 0 0 1 0"


def make(root: Path, n=3, size=(64, 48), right=None, calib=f"P0: {P0}\nP1: {P1}\n", poses=None, names=None):
    """A KITTI-layout folder: ``n`` random left images (and ``right`` right ones), calib.txt, poses.txt."""
    rng = np.random.default_rng(0)
    names = names or ("image_l", "image_r")
    for sub, count in ((names[0], n), (names[1], right)):
        if count is None:
            continue
        (root / sub).mkdir(parents=True)
        for i in range(count):
            cv2.imwrite(str(root / sub / f"{i:06d}.png"), rng.integers(0, 255, size[::-1], dtype=np.uint8))
    if calib is not None:
        (root / "calib.txt").write_text(calib)
    if poses is not None:
        (root / "poses.txt").write_text(poses)
    return root


@pytest.mark.skipif(not KITTI.is_dir(), reason=f"{KITTI} is absent (real data in ../shared/data)")
def test_the_real_kitti_sequence():
    seq = load_kitti_folder(KITTI)
    assert len(seq) == 51 and seq.right is None and not seq.stereo and seq.image_size == (1226, 370)
    assert seq.K[0, 0] == pytest.approx(707.0912) and seq.K[1, 2] == pytest.approx(183.1104)
    assert seq.baseline_m == pytest.approx(379.8145 / 707.0912)
    assert seq.poses.shape == (51, 4, 4) and seq.timestamps_s is None
    assert seq.left[0].name == "000000.png" and seq.left[-1].name == "000050.png"


def test_stereo_folder_with_named_calibration_lines(tmp_path):
    calib = f"P0: {P0}\nP1: {P1}\nP2: {P0}\nTr: 1 2 3\n"
    seq = load_kitti_folder(make(tmp_path, right=3, calib=calib, poses="\n".join([POSE] * 3),
                                 names=("image_0", "image_1")))
    assert seq.stereo and len(seq.right) == 3 and seq.baseline_m == pytest.approx(0.54)
    assert seq.P1[0, 3] == -378 and np.allclose(seq.K, [[700, 0, 320], [0, 700, 240], [0, 0, 1]])
    assert np.allclose(seq.poses, np.eye(4)) and seq.image_size == (64, 48)


def test_unnamed_calibration_lines_are_p0_p1_and_times_are_read(tmp_path):
    make(tmp_path, calib=f"{P0}\n{P1}")
    (tmp_path / "times.txt").write_text("0.0\n0.1\n0.2\n")
    seq = load_kitti_folder(tmp_path)
    assert seq.P0[0, 0] == 700 and seq.baseline_m == pytest.approx(0.54) and seq.poses is None
    assert np.allclose(seq.timestamps_s, [0, 0.1, 0.2])


def test_jpeg_sizes_are_read_too(tmp_path):
    (tmp_path / "image_l").mkdir()
    for i, w in enumerate((80, 80, 96)):
        cv2.imwrite(str(tmp_path / "image_l" / f"{i}.jpg"), np.full((40, w), 128, np.uint8))
    (tmp_path / "calib.txt").write_text(f"P0: {P0}\n")
    with pytest.raises(ValueError, match=r"image_l/2.jpg is 96x40 px but image_l/0.jpg is 80x40"):
        load_kitti_folder(tmp_path)


@pytest.mark.parametrize("build, message", [
    (lambda d: d / "nowhere", "is not a folder"),
    (lambda d: d, "has no image_0/ or image_l/ folder"),
    (lambda d: (d / "image_l").mkdir() or d, "holds no images"),
    (lambda d: make(d, calib=None), "calib.txt is missing"),
    (lambda d: make(d, calib=f"P2: {P0}\n"), "has no P0 line"),
    (lambda d: make(d, calib="P0: 1 2 3\n"), "P0 must be 12 finite numbers"),
    (lambda d: make(d, right=2), "image_r/ has 2 images but image_l/ has 3"),
    (lambda d: make(d, right=3, calib=f"P0: {P0}\n"), "gives no stereo baseline"),
    (lambda d: make(d, right=3, calib=f"P0: {P0}\nP1: {P0}\n"), "gives no stereo baseline"),
    (lambda d: make(d, poses="\n".join([POSE] * 2)), "poses.txt has 2 poses but there are 3 images"),
    (lambda d: make(d, poses="\n".join([POSE, POSE, POSE + " 7"])), "poses.txt line 3: expected 12 finite numbers"),
    (lambda d: make(d, poses="\n".join([POSE, POSE, POSE.replace("0", "nan", 1)])), "line 3: expected 12 finite"),
])
def test_bad_folders_are_one_clear_error(tmp_path, build, message):
    with pytest.raises(ValueError, match=message):
        load_kitti_folder(build(tmp_path))


def test_mixed_image_sizes_name_the_odd_image(tmp_path):
    make(tmp_path)
    cv2.imwrite(str(tmp_path / "image_l" / "000001.png"), np.zeros((50, 64), np.uint8))
    with pytest.raises(ValueError, match=r"image_l/000001.png is 64x50 px but image_l/000000.png is 64x48"):
        load_kitti_folder(tmp_path)
    make(tmp_path / "stereo", right=3, size=(64, 48))
    cv2.imwrite(str(tmp_path / "stereo" / "image_r" / "000002.png"), np.zeros((48, 60), np.uint8))
    with pytest.raises(ValueError, match=r"image_r/000002.png is 60x48 px"):
        load_kitti_folder(tmp_path / "stereo")
