"""Trajectory scoring on trajectories whose errors are known in closed form."""

import math

import numpy as np
import pytest

from percept.odometry import (as_matrices, ate_rmse_m, cumulative_distance_m, final_position_error_m, kitti_drift,
                              path_length_m, rotation_angle_rad)


def straight(n=101, step_m=1.0):
    """Planar poses along +x, ``step_m`` apart, heading 0."""
    s = np.arange(n) * step_m
    return np.stack([s, np.zeros(n), np.zeros(n)], axis=1)


def curve(n=200):
    """A planar S-curve at 0.5 m a frame, heading along the tangent."""
    s = np.arange(n) * 0.5
    yaw = 0.3 * np.sin(s / 15.0)
    dx, dy = 0.5 * np.cos(yaw), 0.5 * np.sin(yaw)
    x = np.concatenate([[0.0], np.cumsum(dx[:-1])])
    y = np.concatenate([[0.0], np.cumsum(dy[:-1])])
    return np.stack([x, y, yaw], axis=1)


def test_as_matrices_planar_is_a_rotation_about_z():
    T = as_matrices([[1.0, 2.0, math.pi / 2]])
    assert T.shape == (1, 4, 4)
    np.testing.assert_allclose(T[0], [[0, -1, 0, 1], [1, 0, 0, 2], [0, 0, 1, 0], [0, 0, 0, 1]], atol=1e-9)
    kitti_rows = as_matrices(T[:, :3, :])
    np.testing.assert_array_equal(kitti_rows, T)  # the rows are copied as they are, the last one appended


def test_bad_poses_raise():
    with pytest.raises(ValueError, match="pair them frame by frame"):
        ate_rmse_m(straight(10), straight(11))
    with pytest.raises(ValueError, match="pair them frame by frame"):
        kitti_drift(straight(10), straight(9))
    with pytest.raises(ValueError, match=r"poses must be \(N, 3\)"):
        as_matrices(np.zeros((5, 2)))
    bad = straight(5)
    bad[2, 0] = np.nan
    with pytest.raises(ValueError, match="finite"):
        final_position_error_m(bad, straight(5))
    with pytest.raises(ValueError, match="step"):
        kitti_drift(straight(5), straight(5), step=0)
    with pytest.raises(ValueError, match="segment lengths"):
        kitti_drift(straight(5), straight(5), lengths_m=[-1.0])


def test_path_length_and_cumulative_distance_of_a_square():
    square = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 0]], dtype=float)
    np.testing.assert_allclose(cumulative_distance_m(square), [0, 1, 2, 3, 4])
    assert path_length_m(square) == pytest.approx(4.0)
    assert path_length_m(np.zeros((0, 3))) == 0.0


def test_exact_trajectory_has_no_error():
    true = curve()
    d = kitti_drift(true, true)
    assert d["segments"] > 0
    # drift is reported to a hundredth of a percent (a hundredth of a degree per 100 m): 1e-9 is rounding alone
    assert d["drift_pct"] == pytest.approx(0.0, abs=1e-9)
    assert d["rot_drift_deg_per_100m"] == pytest.approx(0.0, abs=1e-9)
    assert ate_rmse_m(true, true) == 0.0
    assert final_position_error_m(true, true) == 0.0


def test_one_percent_scale_about_the_start():
    true = straight(101)  # 100 m
    est = true.copy()
    est[:, :2] *= 1.01
    d = kitti_drift(est, true)
    assert d["drift_pct"] == pytest.approx(1.0, abs=1e-9)
    assert d["rot_drift_deg_per_100m"] == pytest.approx(0.0, abs=1e-9)
    # lengths 10, 20, ..., 80 m from first frames 0, 10, ..., 100: (11 - k) segments of 10 k m
    assert d["segments"] == sum(11 - k for k in range(1, 9))
    # frame k is 0.01 k m off: ATE = 0.01 sqrt(sum k^2 / 101) = 0.01 sqrt(100 * 201 / 6)
    assert ate_rmse_m(est, true) == pytest.approx(0.01 * math.sqrt(3350.0), abs=1e-6)  # [m]
    assert final_position_error_m(est, true) == pytest.approx(1.0)
    assert kitti_drift(est, true, lengths_m=[25.0], step=1)["drift_pct"] == pytest.approx(1.0, abs=1e-9)


def test_heading_bias_accumulating_along_a_straight_line():
    k_rad_per_m = 1e-3  # heading error grows by 1 mrad per metre travelled
    true = straight(201, 0.5)
    s = np.arange(201) * 0.5
    # dead reckoning with the biased heading: an arc of curvature k
    est = np.stack([np.sin(k_rad_per_m * s) / k_rad_per_m, (1 - np.cos(k_rad_per_m * s)) / k_rad_per_m,
                    k_rad_per_m * s], axis=1)
    d = kitti_drift(est, true)
    # each segment of length L turns by k L: rotation error k per metre
    assert d["rot_drift_deg_per_100m"] == pytest.approx(math.degrees(k_rad_per_m) * 100.0, rel=1e-6)
    assert d["drift_pct"] > 0.0
    # the segment from the start: chord error |(sin kL / k - L, (1 - cos kL) / k)| / L
    first = kitti_drift(est, true, lengths_m=[50.0], step=1000)
    L = 50.0
    chord_err = math.hypot(math.sin(k_rad_per_m * L) / k_rad_per_m - L, (1 - math.cos(k_rad_per_m * L)) / k_rad_per_m)
    assert first["segments"] == 1
    assert first["drift_pct"] == pytest.approx(100.0 * chord_err / L, rel=1e-6)


def test_planar_and_homogeneous_inputs_agree():
    true = curve()
    est = true.copy()
    est[:, 0] *= 1.02
    est[:, 2] += np.linspace(0.0, 0.05, len(est))
    d_planar = kitti_drift(est, true)
    d_matrix = kitti_drift(as_matrices(est), as_matrices(true))
    assert d_planar == pytest.approx(d_matrix)
    assert ate_rmse_m(est, true) == pytest.approx(ate_rmse_m(as_matrices(est), true))
    assert final_position_error_m(as_matrices(est), as_matrices(true)) == pytest.approx(
        final_position_error_m(est, true))


def test_no_segment_or_no_pose_is_none():
    d = kitti_drift(straight(11), straight(11), lengths_m=[1000.0])
    assert d == {"drift_pct": None, "rot_drift_deg_per_100m": None, "segments": 0}
    standing = np.zeros((5, 3))
    assert kitti_drift(standing, standing)["drift_pct"] is None
    empty = np.zeros((0, 3))
    assert ate_rmse_m(empty, empty) is None
    assert final_position_error_m(empty, empty) is None


def test_rotation_angle_is_accurate_for_small_angles():
    T = as_matrices([[0.0, 0.0, 1e-7], [0.0, 0.0, -2.5]])
    # arccos(trace) would be ~1e-8 rad (10 %) off at 1e-7 rad: 1e-6 of the angle tells the two apart
    np.testing.assert_allclose(rotation_angle_rad(T[:, :3, :3]), [1e-7, 2.5], rtol=1e-6)
