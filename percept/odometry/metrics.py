"""Scoring formulas for trajectories: KITTI drift, ATE, final position error. Pure numpy.

A trajectory is either planar, (N, 3) rows (x_m, y_m, yaw_rad) in the world frame (x forward at
the start, y left, z up; yaw counter-clockwise about +z), or (N, 4, 4) homogeneous world-from-
vehicle transforms ((N, 3, 4) KITTI rows are accepted too). Estimate and truth are paired by index.

References: Geiger, Lenz & Urtasun 2012, "Are we ready for autonomous driving? The KITTI vision
benchmark suite" (CVPR), odometry protocol of its devkit; Sturm et al. 2012, "A benchmark for the
evaluation of RGB-D SLAM systems" (IROS), absolute trajectory error. docs/design.md, "Scoring definitions":
KITTI's protocol with segment lengths scaled to the run's length; ATE RMSE from the known start
pose, no alignment.
"""

from __future__ import annotations

import math

import numpy as np

# KITTI's segment lengths 100, 200, ..., 800 m as fractions of the run's true path length
KITTI_LENGTH_FRACTIONS: tuple[float, ...] = (0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8)


def as_matrices(poses: np.ndarray) -> np.ndarray:
    """(N, 3) planar (x_m, y_m, yaw_rad), (N, 3, 4) or (N, 4, 4) poses -> (N, 4, 4) SE(3) matrices."""
    p = np.asarray(poses, dtype=np.float64)
    if not np.all(np.isfinite(p)):
        raise ValueError("poses must be finite (a NaN or inf is in the trajectory)")
    if p.ndim == 2 and p.shape[1] == 3:
        c, s = np.cos(p[:, 2]), np.sin(p[:, 2])
        out = np.tile(np.eye(4), (len(p), 1, 1))
        # R = R_z(yaw) = [[cos, -sin, 0], [sin, cos, 0], [0, 0, 1]], t = (x, y, 0)
        out[:, 0, 0], out[:, 0, 1], out[:, 1, 0], out[:, 1, 1] = c, -s, s, c
        out[:, 0, 3], out[:, 1, 3] = p[:, 0], p[:, 1]
        return out
    if p.ndim == 3 and p.shape[1:] in ((3, 4), (4, 4)):
        out = np.tile(np.eye(4), (len(p), 1, 1))
        out[:, :3, :] = p[:, :3, :]
        return out
    raise ValueError(f"poses must be (N, 3) as (x_m, y_m, yaw_rad), (N, 3, 4) or (N, 4, 4); got shape {p.shape}")


def _paired(est: np.ndarray, true: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    te, tt = as_matrices(est), as_matrices(true)
    if len(te) != len(tt):
        raise ValueError(f"estimate has {len(te)} poses and truth {len(tt)}: pair them frame by frame")
    return te, tt


def cumulative_distance_m(poses: np.ndarray) -> np.ndarray:
    """(N,) path length from the first pose to each pose [m]; 0 at the first."""
    t = as_matrices(poses)[:, :3, 3]
    # s_k = sum_{i<k} |t_{i+1} - t_i|
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(t, axis=0), axis=1))]) if len(t) else np.zeros(0)


def path_length_m(poses: np.ndarray) -> float:
    """Total path length of a trajectory [m]."""
    s = cumulative_distance_m(poses)
    return float(s[-1]) if len(s) else 0.0


def _relative(T: np.ndarray, i: np.ndarray, j: np.ndarray) -> np.ndarray:
    """Batched T_i^-1 T_j (K, 4, 4): pose of frame j seen from frame i."""
    r_i_t = np.swapaxes(T[i, :3, :3], 1, 2)
    out = np.tile(np.eye(4), (len(i), 1, 1))
    # T_i^-1 T_j = [R_i^T R_j, R_i^T (t_j - t_i)]
    out[:, :3, :3] = r_i_t @ T[j, :3, :3]
    out[:, :3, 3] = np.einsum("kab,kb->ka", r_i_t, T[j, :3, 3] - T[i, :3, 3])
    return out


def rotation_angle_rad(R: np.ndarray) -> np.ndarray:
    """Angle of rotation matrices (..., 3, 3) [rad], in [0, pi]."""
    # cos(a) = (tr R - 1) / 2; sin(a) = |vee(R - R^T)| / 2 (atan2 keeps small angles accurate)
    cos_a = (np.trace(R, axis1=-2, axis2=-1) - 1.0) / 2.0
    vee = np.stack([R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0], R[..., 1, 0] - R[..., 0, 1]], -1)
    return np.arctan2(np.linalg.norm(vee, axis=-1) / 2.0, cos_a)


def _segment_lengths(dist_m: np.ndarray, lengths_m) -> np.ndarray:
    if lengths_m is None:
        total = dist_m[-1] if len(dist_m) else 0.0
        lengths = total * np.asarray(KITTI_LENGTH_FRACTIONS)
        return lengths[lengths > 0.0]
    lengths = np.asarray(lengths_m, dtype=np.float64).reshape(-1)
    if not np.all(np.isfinite(lengths) & (lengths > 0.0)):
        raise ValueError(f"segment lengths must be finite and > 0 m, got {lengths.tolist()}")
    return lengths


def kitti_drift(est: np.ndarray, true: np.ndarray, lengths_m=None, step: int = 10) -> dict:
    """KITTI odometry errors: mean translation drift [%] and rotation drift [deg / 100 m].

    For every first frame i (every ``step`` frames) and segment length L, j is the first frame at
    which the TRUE path length from i reaches L. With the relative error
    E = (T_true_i^-1 T_true_j)^-1 (T_est_i^-1 T_est_j), the segment's errors are |t(E)| / L and
    angle(R(E)) / L, averaged over all segments. Default lengths: the run's true path length times
    ``KITTI_LENGTH_FRACTIONS`` (KITTI's 100..800 m scaled to the run). None when no segment fits.
    """
    te, tt = _paired(est, true)
    if int(step) != step or step < 1:
        raise ValueError(f"step must be a positive whole number of frames, got {step!r}")
    dist = cumulative_distance_m(tt)
    first = np.arange(0, len(tt), int(step))
    t_err, r_err = [], []
    for L in _segment_lengths(dist, lengths_m):
        # j = min { k : s_k - s_i >= L }, L relaxed by 1e-9 so that rounding of s or L cannot skip a frame
        last = np.searchsorted(dist, dist[first] + L * (1.0 - 1e-9), side="left")
        ok = last < len(tt)
        i, j = first[ok], last[ok]
        E = np.linalg.inv(_relative(tt, i, j)) @ _relative(te, i, j)
        # e_t = |t(E)| / L,  e_r = angle(R(E)) / L
        t_err.append(np.linalg.norm(E[:, :3, 3], axis=1) / L)
        r_err.append(rotation_angle_rad(E[:, :3, :3]) / L)
    t_all = np.concatenate(t_err) if t_err else np.zeros(0)
    r_all = np.concatenate(r_err) if r_err else np.zeros(0)
    if not t_all.size:
        return {"drift_pct": None, "rot_drift_deg_per_100m": None, "segments": 0}
    return {"drift_pct": float(100.0 * t_all.mean()),
            "rot_drift_deg_per_100m": float(100.0 * math.degrees(r_all.mean())),
            "segments": int(t_all.size)}


def ate_rmse_m(est: np.ndarray, true: np.ndarray) -> float | None:
    """Absolute trajectory error [m]: RMSE of the position difference frame by frame, no alignment.

    Both trajectories are in the same world frame: the estimate starts from the known start pose.
    None for an empty trajectory.
    """
    te, tt = _paired(est, true)
    if not len(te):
        return None
    # ATE = sqrt( (1/N) sum_k |t_est_k - t_true_k|^2 )
    return float(np.sqrt(np.mean(np.sum((te[:, :3, 3] - tt[:, :3, 3]) ** 2, axis=1))))


def final_position_error_m(est: np.ndarray, true: np.ndarray) -> float | None:
    """|t_est - t_true| at the last frame [m]; None for an empty trajectory."""
    te, tt = _paired(est, true)
    return float(np.linalg.norm(te[-1, :3, 3] - tt[-1, :3, 3])) if len(te) else None
