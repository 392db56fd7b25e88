"""`percept odometry`: the real KITTI sequence (mono), a synthetic stereo sequence, trajectory files, the plot;
bad input is one line and exit code 2."""

import json
from pathlib import Path

import cv2
import numpy as np
import pytest
from typer.testing import CliRunner

from percept.cli import app
from percept.odometry import read_kitti_poses, read_tum

runner = CliRunner()
KITTI = Path(__file__).resolve().parents[2] / ".." / "shared" / "data" / "kitti-odometry-seq"
SCORES = ("true_path_length_m", "ate_rmse_m", "drift_pct", "rot_drift_deg_per_100m", "final_error_m",
          "final_error_pct_of_path")
P0 = "300 0 160 0 0 300 120 0 0 0 1 0"



@pytest.fixture(scope="module")
def kitti(tmp_path_factory):
    """One run over the real sequence with every output: (result, output folder)."""
    if not KITTI.is_dir():
        pytest.skip(f"{KITTI} is absent (real data in ../shared/data)")
    out = tmp_path_factory.mktemp("odometry")
    r = runner.invoke(app, ["odometry", str(KITTI), "--json", str(out / "o.json"), "--poses-out",
                            str(out / "poses.tum"), "--format", "tum", "--out", str(out / "plots")])
    return r, out


@pytest.mark.slow
def test_kitti_mono_json_is_scored_within_3_percent(kitti):
    r, out = kitti
    assert r.exit_code == 0, r.output
    d = json.loads((out / "o.json").read_text())
    assert d["mode"] == "mono" and d["frames"] == 51 and d["steps_failed"] == 0
    assert all(d[k] is not None for k in SCORES)
    assert d["final_error_pct_of_path"] <= 3.0 and d["true_path_length_m"] == pytest.approx(59.86, abs=0.01)
    assert d["path_length_m"] == pytest.approx(d["true_path_length_m"], rel=0.03)
    assert "mono odometry on 51 frames" in r.output and "final error" in r.output


@pytest.mark.slow
def test_kitti_tum_output_parses_back_and_starts_at_the_true_first_pose(kitti):
    _, out = kitti
    rows = [line.split() for line in (out / "poses.tum").read_text().splitlines() if not line.startswith("#")]
    assert len(rows) == 51 and {len(row) for row in rows} == {8}
    times, poses = read_tum(out / "poses.tum")
    assert np.allclose(times, 0.1 * np.arange(51))  # no times.txt: KITTI's 10 Hz
    true = read_kitti_poses(KITTI / "poses.txt")
    assert np.allclose(poses[0], true[0], atol=1e-8)
    assert np.linalg.norm(poses[-1, :3, 3] - true[-1, :3, 3]) < 0.03 * 59.86


@pytest.mark.slow
def test_kitti_plot_is_written(kitti):
    _, out = kitti
    img = cv2.imread(str(out / "plots" / "trajectory.png"))
    assert img.shape == (720, 720, 3)
    blue, red = (img[..., 0] > 150) & (img[..., 2] < 80), (img[..., 2] > 180) & (img[..., 0] < 60)
    assert blue.sum() > 500 and red.sum() > 500  # both paths drawn


def make_stereo(root: Path, n=6, f=300.0, b=0.5, step_m=0.5, z0=12.0, size=(320, 240), poses=True):
    """A rectified pair moving straight towards a textured wall at z0 - step_m k [m]: image_0/, image_1/,
    calib.txt and (with ``poses``) poses.txt."""
    w, h = size
    tex = cv2.GaussianBlur(np.random.default_rng(3).integers(0, 255, (1200, 1200), dtype=np.uint8), (0, 0), 2.0)
    tex = cv2.normalize(tex, None, 0, 255, cv2.NORM_MINMAX)
    u, v = np.meshgrid(np.arange(w, dtype=np.float32), np.arange(h, dtype=np.float32))
    for k in range(n):
        z = z0 - step_m * k
        for sub, x_cam in (("image_0", 0.0), ("image_1", b)):
            (root / sub).mkdir(parents=True, exist_ok=True)
            # wall point seen at pixel (u, v): X = (u - cx) Z / f + camera x, Y = (v - cy) Z / f; 60 texels a metre
            mx, my = ((u - w / 2) * z / f + x_cam) * 60 + 600, (v - h / 2) * z / f * 60 + 600
            cv2.imwrite(str(root / sub / f"{k:06d}.png"), cv2.remap(tex, mx, my, cv2.INTER_LINEAR))
    # P1[0, 3] = -fx b
    (root / "calib.txt").write_text(f"P0: {P0}\nP1: {f} 0 {w / 2} {-f * b} 0 {f} {h / 2} 0 0 0 1 0\n")
    if poses:
        (root / "poses.txt").write_text("\n".join(f"1 0 0 0 0 1 0 0 0 0 1 {step_m * k}" for k in range(n)))
    return root


def test_stereo_folder_runs_stereo_and_writes_kitti_poses(tmp_path):
    make_stereo(tmp_path / "seq")
    r = runner.invoke(app, ["odometry", str(tmp_path / "seq"), "--json", str(tmp_path / "s.json"), "--poses-out",
                            str(tmp_path / "p.txt")])
    assert r.exit_code == 0, r.output
    d = json.loads((tmp_path / "s.json").read_text())
    assert d["mode"] == "stereo" and d["frames"] == 6 and d["baseline_m"] == pytest.approx(0.5)
    assert d["true_path_length_m"] == pytest.approx(2.5) and d["final_error_m"] < 0.25
    poses = read_kitti_poses(tmp_path / "p.txt")
    assert poses.shape == (6, 4, 4) and poses[-1, 2, 3] == pytest.approx(2.5, abs=0.25)


def test_without_poses_the_scores_are_null_and_failed_steps_counted(tmp_path):
    make_stereo(tmp_path / "seq", n=3, poses=False)
    for k in range(3):  # monocular now: the right camera removed, and nothing the mono VO can measure
        (tmp_path / "seq" / "image_1" / f"{k:06d}.png").unlink()
        cv2.imwrite(str(tmp_path / "seq" / "image_0" / f"{k:06d}.png"), np.zeros((240, 320), np.uint8))
    (tmp_path / "seq" / "image_1").rmdir()
    r = runner.invoke(app, ["odometry", str(tmp_path / "seq"), "--json", str(tmp_path / "m.json"), "--poses-out",
                            str(tmp_path / "p.txt"), "--out", str(tmp_path)])
    assert r.exit_code == 0, r.output
    d = json.loads((tmp_path / "m.json").read_text())
    assert d["mode"] == "mono" and d["frames"] == 3 and d["steps_failed"] == 2 and d["path_length_m"] == 0.0
    assert all(d[k] is None for k in SCORES) and sum(d["failure_reasons"].values()) == 2
    assert np.allclose(read_kitti_poses(tmp_path / "p.txt"), np.eye(4)) and (tmp_path / "trajectory.png").is_file()


def bad_folder(root: Path, kind: str) -> Path:
    make_stereo(root, n=3)
    if kind == "no images":
        for p in (root / "image_0").iterdir():
            p.unlink()
    elif kind == "no P0":
        (root / "calib.txt").write_text(f"P2: {P0}\n")
    elif kind == "mixed sizes":
        cv2.imwrite(str(root / "image_0" / "000001.png"), np.zeros((200, 320), np.uint8))
    elif kind == "poses length":
        (root / "poses.txt").write_text("\n".join(["1 0 0 0 0 1 0 0 0 0 1 0"] * 5))
    return root


@pytest.mark.parametrize("kind, message", [("no images", "holds no images"), ("no P0", "has no P0 line"),
                                           ("mixed sizes", "image_0/000001.png is 320x200 px but"),
                                           ("poses length", "has 5 poses but there are 3 images")])
def test_bad_folders_are_one_line_and_exit_2(tmp_path, kind, message, one_line_error):
    folder = bad_folder(tmp_path / "seq", kind)
    one_line_error(runner.invoke(app, ["odometry", str(folder), "--json", str(tmp_path / "o.json")]), message)
    assert not (tmp_path / "o.json").exists()


def test_bad_options_are_one_line_and_exit_2(tmp_path, one_line_error):
    one_line_error(runner.invoke(app, ["odometry", str(tmp_path / "none")]), "is not a folder")
    folder = make_stereo(tmp_path / "seq", n=2)
    one_line_error(runner.invoke(app, ["odometry", str(folder), "--camera-height", "0"]), "--camera-height")
    (tmp_path / "file").write_text("")
    one_line_error(runner.invoke(app, ["odometry", str(folder), "--out", str(tmp_path / "file")]), "is a file")
    one_line_error(runner.invoke(app, ["odometry", str(folder), "--poses-out", str(folder / "poses.txt")]),
                   "is also an input")
