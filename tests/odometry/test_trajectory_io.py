"""Trajectory files: KITTI and TUM round trips, the TUM layout that evo and the TUM tools read, bad files."""

from pathlib import Path

import numpy as np
import pytest

from percept.odometry import TrajectoryFormat, read_kitti_poses, read_tum, write_trajectory
from percept.odometry.trajectory_io import quaternion_to_rotation, rotation_to_quaternion

KITTI_POSES = Path(__file__).resolve().parents[2] / ".." / "shared" / "data" / "kitti-odometry-seq" / "poses.txt"


def rot(axis, angle):
    """Rotation matrix of ``angle`` [rad] about the unit vector ``axis`` (Rodrigues)."""
    k = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def random_poses(n, seed=0):
    rng = np.random.default_rng(seed)
    T = np.tile(np.eye(4), (n, 1, 1))
    for i in range(n):
        T[i, :3, :3] = rot(rng.normal(size=3), rng.uniform(0, np.pi))
        T[i, :3, 3] = rng.normal(scale=20, size=3)
    return T


@pytest.mark.parametrize("R", [np.eye(3), rot([0, 0, 1], np.pi / 2), rot([1, 0, 0], np.pi), rot([0, 1, 0], np.pi),
                               rot([0, 0, 1], np.pi), rot([1, 1, 0], 3.1), rot([1, -2, 3], 0.7)])
def test_quaternion_round_trip_on_every_branch_of_shepperds_method(R):
    q = rotation_to_quaternion(R)
    assert np.isclose(np.linalg.norm(q), 1.0) and q[3] >= 0
    assert np.allclose(quaternion_to_rotation(q), R, atol=1e-9)


def test_quaternion_is_x_y_z_w():
    s = np.sqrt(0.5)
    assert np.allclose(rotation_to_quaternion(rot([0, 0, 1], np.pi / 2)), [0, 0, s, s])
    assert np.allclose(rotation_to_quaternion(np.eye(3)), [0, 0, 0, 1])


def test_kitti_round_trip(tmp_path):
    T = random_poses(20)
    write_trajectory(tmp_path / "p.txt", T, None, TrajectoryFormat.KITTI)
    lines = (tmp_path / "p.txt").read_text().splitlines()
    assert len(lines) == 20 and all(len(line.split()) == 12 for line in lines)
    assert np.allclose(read_kitti_poses(tmp_path / "p.txt"), T, atol=1e-8)


def test_tum_round_trip_and_layout(tmp_path):
    T = random_poses(15, seed=1)
    T[0] = np.eye(4)
    T[1, :3, :3] = rot([0, 0, 1], np.pi / 2)
    t = 1.5 + 0.1 * np.arange(15)
    write_trajectory(tmp_path / "p.tum", T, t, "tum")
    rows = [line.split() for line in (tmp_path / "p.tum").read_text().splitlines() if not line.startswith("#")]
    assert len(rows) == 15 and all(len(r) == 8 for r in rows)  # timestamp tx ty tz qx qy qz qw
    values = np.array(rows, float)
    assert np.allclose(np.linalg.norm(values[:, 4:], axis=1), 1.0, atol=1e-8)
    assert np.allclose(values[0, 4:], [0, 0, 0, 1]) and np.allclose(values[1, 4:], [0, 0, np.sqrt(.5), np.sqrt(.5)])
    assert np.allclose(values[:, 1:4], T[:, :3, 3], atol=1e-8)
    times, back = read_tum(tmp_path / "p.tum")
    assert np.allclose(times, t) and np.allclose(back, T, atol=1e-8)


def test_bad_poses_raise_before_writing_and_keep_the_old_file(tmp_path):
    target = tmp_path / "p.txt"
    target.write_text("old")
    T = random_poses(3)
    T[1, 0, 3] = np.nan
    with pytest.raises(ValueError, match="finite"):
        write_trajectory(target, T, None, TrajectoryFormat.KITTI)
    with pytest.raises(ValueError, match="one timestamp per pose"):
        write_trajectory(target, random_poses(3), [0.0, 1.0], TrajectoryFormat.TUM)
    with pytest.raises(ValueError, match="strictly increasing"):
        write_trajectory(target, random_poses(3), [0.0, 1.0, 1.0], TrajectoryFormat.TUM)
    skewed = random_poses(3)
    skewed[2, :3, :3] *= 2.0
    with pytest.raises(ValueError, match="pose 2 has no rotation"):
        write_trajectory(target, skewed, None, TrajectoryFormat.KITTI)
    assert target.read_text() == "old" and sorted(p.name for p in tmp_path.iterdir()) == ["p.txt"]


def test_bad_files_name_the_line(tmp_path):
    good = " ".join(["1", "0", "0", "0", "0", "1", "0", "0", "0", "0", "1", "0"])
    (tmp_path / "k.txt").write_text(f"{good}\n{good} 5\n")
    with pytest.raises(ValueError, match="line 2: expected 12 finite numbers"):
        read_kitti_poses(tmp_path / "k.txt")
    (tmp_path / "k.txt").write_text(good.replace("1", "3", 1))
    with pytest.raises(ValueError, match="line 1: the 3x3 block is not a rotation"):
        read_kitti_poses(tmp_path / "k.txt")
    (tmp_path / "t.txt").write_text("# comment\n\n0 1 2 3 0 0 0 1\n1 1 2 3 0 0 0 0\n")
    with pytest.raises(ValueError, match="line 4: quaternion"):
        read_tum(tmp_path / "t.txt")
    (tmp_path / "t.txt").write_text("# only a comment\n")
    with pytest.raises(ValueError, match="holds no poses"):
        read_tum(tmp_path / "t.txt")
    with pytest.raises(ValueError, match="cannot read"):
        read_tum(tmp_path / "missing.txt")


def test_tum_quaternions_are_normalised_on_reading(tmp_path):
    (tmp_path / "t.txt").write_text("0.5 1 2 3 0 0 0 2\n")
    t, T = read_tum(tmp_path / "t.txt")
    assert t.tolist() == [0.5] and np.allclose(T[0], [[1, 0, 0, 1], [0, 1, 0, 2], [0, 0, 1, 3], [0, 0, 0, 1]])


@pytest.mark.skipif(not KITTI_POSES.is_file(), reason=f"{KITTI_POSES} is absent (real data in ../shared/data)")
def test_reads_kitti_ground_truth_without_a_final_newline():
    T = read_kitti_poses(KITTI_POSES)
    assert T.shape == (51, 4, 4) and np.allclose(T[0], np.eye(4), atol=1e-9)
    assert T[-1, 2, 3] == pytest.approx(59.83857)
