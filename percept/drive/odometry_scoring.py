"""Scoring the odometry task: every trajectory the vision slot reports, side by side, against the true path.

KITTI's drift (segment lengths scaled to the run), ATE RMSE from the known start pose and the final position
error for visual odometry alone, dead reckoning (IMU + wheel speed), fused (+ VO) and the slot's estimate
(+ landmark fixes); consistency: the share of frames whose position error lies inside the filter's 3-sigma
ellipse (normalised estimation error squared <= chi2(2 dof, 99.73 %) = 11.83).
"""

from __future__ import annotations

import numpy as np

from percept.odometry.metrics import ate_rmse_m, final_position_error_m, kitti_drift, path_length_m

from .rows import Rows

# P(chi2 with 2 dof <= 11.83) = 0.9973, the probability of a 1-D +-3 sigma interval
NEES_3SIGMA_2DOF = 11.83
TRAJECTORIES = ("vo", "dead_reckoning", "fused", "landmarks")
"""The trajectories scored, each under its own keys: VO alone, dead reckoning, fused, the slot's estimate."""
TRAJECTORY_EVERY = 15
"""The run JSON keeps one pose in this many frames of each trajectory (for plots), rounded to 1 cm."""


def _pose(p) -> tuple[float, float, float]:
    return p.x_m, p.y_m, p.yaw_rad


def inside_3sigma(errors_xy: np.ndarray, covariances: np.ndarray) -> float | None:
    """Share of frames whose (N, 2) position error is inside the (N, 2, 2) covariance's 3-sigma ellipse."""
    if not len(errors_xy):
        return None
    # NEES_k = e_k^T P_k^-1 e_k, with a floor on P for the exactly known start
    P = covariances + np.eye(2) * 1e-9
    nees = np.einsum("ki,kij,kj->k", errors_xy, np.linalg.inv(P), errors_xy)
    return float(np.mean(nees <= NEES_3SIGMA_2DOF))


class OdometryScorer:
    """Collects the true pose and each trajectory of the vision slot (``OdometryDebug``) frame by frame."""

    def __init__(self, ctx):
        self.ctx = ctx
        self.true = Rows(3)  # x [m], y [m], yaw [rad]
        self.paths = {k: Rows(3) for k in TRAJECTORIES}
        self.cov = {"fused": Rows(4), "landmarks": Rows(4)}  # the (x, y) block of the covariance [m²], row-major
        self.fixes = self.sightings = self.vo_failed = 0

    def update(self, pose, debug, step) -> None:
        if not self.ctx.vision or pose is None or debug is None:
            return
        e = step.truth.ego
        self.true.append((e.x_m, e.y_m, e.yaw_rad))
        for key, p in (("vo", debug.vo_pose), ("dead_reckoning", debug.dead_reckoning_pose),
                       ("fused", debug.fused_pose), ("landmarks", pose.pose)):
            self.paths[key].append(_pose(p))
        self.cov["fused"].append(debug.fused_covariance[:2, :2].ravel())
        self.cov["landmarks"].append(pose.covariance[:2, :2].ravel())
        self.fixes += debug.fixes
        self.sightings += len(debug.sightings)
        self.vo_failed += int(len(self.true) > 1 and not debug.vo_step.ok)

    @staticmethod
    def _trajectory(true: np.ndarray, est: dict[str, np.ndarray]) -> dict:
        """x, y [m] of the truth and of each trajectory every TRAJECTORY_EVERY frames (and the last frame)."""
        idx = sorted(set(range(0, len(true), TRAJECTORY_EVERY)) | {len(true) - 1})
        paths = {"true": true, "estimate": est["landmarks"], **{k: est[k] for k in ("fused", "vo", "dead_reckoning")}}
        return {"every_frames": TRAJECTORY_EVERY,
                **{k: np.round(p[idx, :2], 2).tolist() for k, p in paths.items()}}

    def result(self) -> dict:
        keys = [f"{m}_{k}" for k in TRAJECTORIES for m in ("drift_pct", "rot_drift_deg_per_100m")]
        keys += [f"{m}_{k}_m" for k in TRAJECTORIES for m in ("ate_rmse", "final_error")]
        keys += ["consistency_3sigma", "consistency_3sigma_fused", "path_length_m", "landmark_fixes",
                 "landmark_sightings", "vo_failed_frames", "trajectory"]
        if len(self.true) < 2:
            return dict.fromkeys(keys)
        true = self.true.values()
        paths = {k: p.values() for k, p in self.paths.items()}
        out: dict = {}
        for k, est in paths.items():
            drift = kitti_drift(est, true)
            out[f"drift_pct_{k}"] = drift["drift_pct"]
            out[f"rot_drift_deg_per_100m_{k}"] = drift["rot_drift_deg_per_100m"]
            out[f"ate_rmse_{k}_m"] = ate_rmse_m(est, true)
            out[f"final_error_{k}_m"] = final_position_error_m(est, true)
        for key, k in (("consistency_3sigma", "landmarks"), ("consistency_3sigma_fused", "fused")):
            out[key] = inside_3sigma(paths[k][:, :2] - true[:, :2], self.cov[k].values().reshape(-1, 2, 2))
        out.update(path_length_m=path_length_m(true), landmark_fixes=self.fixes, landmark_sightings=self.sightings,
                   vo_failed_frames=self.vo_failed, trajectory=self._trajectory(true, paths))
        return {k: out[k] for k in keys}
