"""Records between the odometry stages: one visual-odometry step."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

# Covariance reported when a step could not be measured: 1 rad and 10 m standard deviation per axis
FAILED_COVARIANCE = np.diag([1.0, 1.0, 1.0, 100.0, 100.0, 100.0])


@dataclass(frozen=True)
class VOStep:
    """Camera motion from the previous processed frame to this one.

    T_prev_cur: (4, 4) pose of the current camera in the previous camera's frame (OpenCV camera axes: x right,
    y down, z forward; translation in metres), so that ``p_prev = T_prev_cur @ p_cur``; identity when not ok.
    covariance: (6, 6) of (rotation vector [rad], translation [m]) of T_prev_cur.
    ok: the motion was measured; tracked: features tracked into this frame; inliers: the geometric fit's inliers;
    quality: inlier share in [0, 1]; keyframe: this frame started a new keyframe; reason: why not ok ("" when ok);
    T_key_cur, key_covariance: (4, 4) pose of the current camera in the frame of the keyframe it was measured
    against, and its (6, 6) covariance (None when not measured, or when the estimator has no keyframes). Steps
    chained from one keyframe share its errors; poses against successive keyframes do not, which is what a filter
    should be given. noise_grey: the image noise's sigma measured at the keyframe [grey levels] (None: not
    measured).
    """

    T_prev_cur: np.ndarray
    covariance: np.ndarray
    ok: bool
    tracked: int = 0
    inliers: int = 0
    quality: float = 0.0
    keyframe: bool = False
    reason: str = ""
    T_key_cur: np.ndarray | None = None
    key_covariance: np.ndarray | None = None
    noise_grey: float | None = None

    @classmethod
    def failed(cls, reason: str, tracked: int = 0, keyframe: bool = False) -> "VOStep":
        """No motion measured (dark, featureless or dropped frame; too few inliers)."""
        return cls(np.eye(4), FAILED_COVARIANCE.copy(), False, tracked, 0, 0.0, keyframe, reason)


@dataclass(frozen=True)
class Trajectory:
    """Camera poses in the first camera's frame: poses (N, 4, 4) world-from-camera [m]; timestamps_s (N,);
    ok (N,) bool: the step into each pose was measured (the first pose is the origin, True)."""

    poses: np.ndarray
    timestamps_s: np.ndarray
    ok: np.ndarray = field(default_factory=lambda: np.zeros(0, bool))

    def __post_init__(self) -> None:
        p = np.asarray(self.poses, dtype=np.float64).reshape(-1, 4, 4)
        t = np.asarray(self.timestamps_s, dtype=np.float64).reshape(-1)
        if len(p) != len(t):
            raise ValueError(f"trajectory has {len(p)} poses but {len(t)} timestamps")
        ok = np.asarray(self.ok, bool).reshape(-1) if len(self.ok) else np.ones(len(p), bool)
        object.__setattr__(self, "poses", p)
        object.__setattr__(self, "timestamps_s", t)
        object.__setattr__(self, "ok", ok)

    def __len__(self) -> int:
        return len(self.poses)
