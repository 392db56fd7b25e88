"""Trajectory files: KITTI and TUM formats, written atomically (temporary file, then rename).

KITTI (odometry devkit, ``poses/XX.txt``): one line per pose, the 12 numbers of the row-major 3x4
world-from-camera matrix [R | t]. TUM (Sturm et al. 2012, the RGB-D benchmark's ``groundtruth.txt``, read by evo
and the TUM tools): one line per pose, ``timestamp tx ty tz qx qy qz qw`` (the quaternion last, w last, unit norm),
``#`` comment lines allowed. Rotation to quaternion by Shepperd's method (Shepperd 1978, "Quaternion from rotation
matrix", J. Guidance and Control): from the largest of the four squared components, so that no division is by a
small number.
"""

from __future__ import annotations

from enum import Enum
from pathlib import Path

import numpy as np

from percept.outputs import write_text_atomic

ROTATION_TOLERANCE = 1e-3
"""Largest |R^T R - I| (any element) and |det R - 1| of a pose written or read."""


class TrajectoryFormat(str, Enum):
    """A trajectory file's layout: KITTI (12 numbers a line) or TUM (timestamp, position, quaternion)."""

    KITTI = "kitti"
    TUM = "tum"


def rotation_to_quaternion(R: np.ndarray) -> np.ndarray:
    """(qx, qy, qz, qw) unit quaternion of a rotation matrix (3, 3), with qw >= 0 (Shepperd's method)."""
    R = np.asarray(R, dtype=np.float64)
    # 4 q_i^2 for i = w, x, y, z: 1 + tr R, 1 + 2 R_ii - tr R
    tr = np.trace(R)
    sq = np.array([1 + tr, 1 + 2 * R[0, 0] - tr, 1 + 2 * R[1, 1] - tr, 1 + 2 * R[2, 2] - tr])
    i = int(np.argmax(sq))
    r = 0.5 * np.sqrt(max(sq[i], 0.0))
    # off-diagonal sums and differences: 4 q_w q_x = R21 - R12, 4 q_x q_y = R01 + R10, ...
    d = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]]) / (4 * r)
    s = np.array([R[0, 1] + R[1, 0], R[0, 2] + R[2, 0], R[1, 2] + R[2, 1]]) / (4 * r)
    w, x, y, z = [(r, *d), (d[0], r, s[0], s[1]), (d[1], s[0], r, s[2]), (d[2], s[1], s[2], r)][i]
    q = np.array([x, y, z, w]) / np.linalg.norm([x, y, z, w])
    return -q if q[3] < 0 else q


def quaternion_to_rotation(q: np.ndarray) -> np.ndarray:
    """(3, 3) rotation of a quaternion (qx, qy, qz, qw) (normalised first); ValueError for a zero quaternion."""
    q = np.asarray(q, dtype=np.float64)
    n = np.linalg.norm(q)
    if not np.isfinite(n) or n < 1e-9:
        raise ValueError(f"quaternion {q.tolist()} has no direction (zero or not finite)")
    x, y, z, w = q / n
    # R = I + 2 w [v]x + 2 [v]x^2, v = (x, y, z)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def _check_poses(poses: np.ndarray) -> np.ndarray:
    """(N, 4, 4) from (N, 4, 4) or (N, 3, 4) poses; ValueError unless finite with rotation blocks."""
    p = np.asarray(poses, dtype=np.float64)
    if p.ndim != 3 or p.shape[1:] not in ((3, 4), (4, 4)) or not len(p):
        raise ValueError(f"poses must be (N, 4, 4) or (N, 3, 4) with N >= 1, got shape {p.shape}")
    if not np.all(np.isfinite(p)):
        raise ValueError("poses must be finite (a NaN or inf is in the trajectory)")
    out = np.tile(np.eye(4), (len(p), 1, 1))
    out[:, :3] = p[:, :3]
    bad = _first_non_rotation(out)
    if bad is not None:
        raise ValueError(f"pose {bad} has no rotation in its 3x3 block (R^T R != I or det R != 1)")
    return out


def _first_non_rotation(T: np.ndarray) -> int | None:
    """Index of the first pose (N, 4, 4) whose 3x3 block is not a rotation, or None."""
    R = T[:, :3, :3]
    ortho = np.abs(np.swapaxes(R, 1, 2) @ R - np.eye(3)).max(axis=(1, 2))
    bad = np.flatnonzero((ortho > ROTATION_TOLERANCE) | (np.abs(np.linalg.det(R) - 1) > ROTATION_TOLERANCE))
    return int(bad[0]) if len(bad) else None


def format_trajectory(poses: np.ndarray, timestamps_s: np.ndarray | None, fmt: TrajectoryFormat) -> str:
    """The text of a trajectory file: poses (N, 4, 4) world-from-camera [m]; timestamps_s (N,) [s], strictly
    increasing (TUM only; KITTI files have none and ignore them)."""
    T = _check_poses(poses)
    fmt = TrajectoryFormat(fmt)
    if fmt is TrajectoryFormat.KITTI:
        return "".join(" ".join(f"{v:.9e}" for v in P[:3].ravel()) + "\n" for P in T)
    t = np.asarray(timestamps_s if timestamps_s is not None else [], dtype=np.float64).reshape(-1)
    if len(t) != len(T):
        raise ValueError(f"a TUM file needs one timestamp per pose: {len(T)} poses, {len(t)} timestamps")
    if not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise ValueError("TUM timestamps must be finite and strictly increasing")
    lines = ["# timestamp tx ty tz qx qy qz qw\n"]
    for ts, P in zip(t, T):
        q = rotation_to_quaternion(P[:3, :3])
        # values that round to zero are written as 0 (not -0.000000000)
        lines.append(" ".join(f"{v if abs(v) >= 5e-10 else 0.0:.9f}" for v in (ts, *P[:3, 3], *q)) + "\n")
    return "".join(lines)


def write_trajectory(path: Path | str, poses: np.ndarray, timestamps_s: np.ndarray | None,
                     fmt: TrajectoryFormat) -> None:
    """Write a trajectory file in ``fmt`` atomically (complete or not at all); see ``format_trajectory``.
    ValueError for bad poses or timestamps (before anything is written), OSError when the disk refuses."""
    write_text_atomic(path, format_trajectory(poses, timestamps_s, fmt))


def _rows(path: Path | str, width: int, what: str) -> list[tuple[int, np.ndarray]]:
    """(line number, numbers) of every non-blank, non-comment line, each ``width`` finite numbers."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError as e:
        raise ValueError(f"cannot read {path} ({e.strerror or e})") from None
    rows = []
    for k, line in enumerate(text.splitlines(), start=1):
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        try:
            v = np.array([float(x) for x in line.split()])
        except ValueError:
            v = np.zeros(0)
        if len(v) != width or not np.all(np.isfinite(v)):
            raise ValueError(f"{path} line {k}: expected {width} finite numbers ({what}), got {line.strip()[:60]!r}")
        rows.append((k, v))
    if not rows:
        raise ValueError(f"{path} holds no poses")
    return rows


def _checked(path, rows: list, T: np.ndarray) -> np.ndarray:
    """``T`` when every pose has a rotation block; ValueError naming the file's line otherwise."""
    bad = _first_non_rotation(T)
    if bad is not None:
        raise ValueError(f"{path} line {rows[bad][0]}: the 3x3 block is not a rotation (R^T R != I or det R != 1)")
    return T


def read_kitti_poses(path: Path | str) -> np.ndarray:
    """(N, 4, 4) world-from-camera poses [m] of a KITTI pose file; ValueError naming the line that is not 12
    finite numbers with a rotation block."""
    rows = _rows(path, 12, "a row-major 3x4 pose")
    T = np.tile(np.eye(4), (len(rows), 1, 1))
    T[:, :3] = np.stack([v for _, v in rows]).reshape(-1, 3, 4)
    return _checked(path, rows, T)


def read_tum(path: Path | str) -> tuple[np.ndarray, np.ndarray]:
    """(timestamps_s (N,), poses (N, 4, 4) world-from-camera [m]) of a TUM trajectory file (``#`` lines skipped,
    quaternions normalised); ValueError naming a bad line."""
    rows = _rows(path, 8, "timestamp tx ty tz qx qy qz qw")
    T = np.tile(np.eye(4), (len(rows), 1, 1))
    for i, (k, v) in enumerate(rows):
        try:
            T[i, :3, :3] = quaternion_to_rotation(v[4:])
        except ValueError as e:
            raise ValueError(f"{path} line {k}: {e}") from None
        T[i, :3, 3] = v[1:4]
    return np.array([v[0] for _, v in rows]), _checked(path, rows, T)
