"""The stereo VO's keyframe spans against the truth: how far each span's motion is off, and how that compares with
the covariance the span claims (the figures behind ``FusionNoise``'s VO terms).

Drives a scenario with only the odometry slot on vision (the others privileged), and records every relative update
the fused filter receives (the span's dx, dy, dyaw in the vehicle frame of the span's start, with its covariance
before the filter's scale factors) and the true poses at the span's two ends.

usage: python tools/vo_span_errors.py SCENARIO SEEDS [CONDITION]     e.g.  python tools/vo_span_errors.py loop 0,1
Prints one JSON line: n (spans), span_frames_median; along_std_m, across_std_m, yaw_std_rad (the spans' errors);
along_rel_std (the along-track error over the span's length); z2_median, z2_p90 (a span's squared translation error
over its own variance, x and y pooled, before the scale factors) and z2_mean (what a scale factor fitted to the
mean would be). Spans shorter than 0.5 m (a car standing) are left out of the relative figures.
"""
import json
import math
import sys

import cv2
import numpy as np

import percept.odometry.fusion as fusion
from percept.drive.config import DriveConfig
from percept.drive.loop import run_drive
from percept.drive.tasks import TASKS
from percept.sensors import PoseEstimate
from percept.sims import SimWorld, WorldConfig


def spans(scenario: str, seed: int, condition: str) -> list[tuple[np.ndarray, np.ndarray, float, int]]:
    """(error (3,), claimed covariance (3, 3), true length [m], frames) of every span the fused filter received."""
    poses: list[tuple[float, float, float]] = []
    clones: dict[int, int] = {}
    updates = []
    observe, clone, relative = SimWorld.observe, fusion.PoseFilter.clone, fusion.PoseFilter.update_relative

    def observed(self, *a, **k):
        frame, gt = observe(self, *a, **k)
        poses.append((gt.ego.x_m, gt.ego.y_m, gt.ego.yaw_rad))
        return frame, gt

    def cloned(self):
        clones[id(self)] = len(poses) - 1
        return clone(self)

    def measured(self, dx, dy, dyaw, cov):
        updates.append((id(self), clones.get(id(self)), len(poses) - 1, dx, dy, dyaw, np.array(cov)))
        return relative(self, dx, dy, dyaw, cov)

    SimWorld.observe, fusion.PoseFilter.clone, fusion.PoseFilter.update_relative = observed, cloned, measured
    try:
        # the task that provides the pose on vision, the others privileged
        vision = {t.name: "vision" for t in TASKS if t.provides is PoseEstimate}
        run_drive(DriveConfig(WorldConfig(scenario, seed=seed, condition=condition), sources=vision,
                              default="privileged"))
    finally:
        SimWorld.observe, fusion.PoseFilter.clone, fusion.PoseFilter.update_relative = observe, clone, relative
    out = []
    first = updates[0][0] if updates else None  # the slot's filters all receive each span: keep one
    for who, start, end, dx, dy, dyaw, cov in updates:
        if who != first or start is None:
            continue
        (x0, y0, a0), (x1, y1, a1) = poses[start], poses[end]
        c, s = math.cos(a0), math.sin(a0)
        # the true motion in the span's starting vehicle frame: R(-yaw0) (p1 - p0), yaw1 - yaw0
        tx, ty = c * (x1 - x0) + s * (y1 - y0), -s * (x1 - x0) + c * (y1 - y0)
        ta = math.atan2(math.sin(a1 - a0), math.cos(a1 - a0))
        err = np.array([dx - tx, dy - ty, math.atan2(math.sin(dyaw - ta), math.cos(dyaw - ta))])
        out.append((err, cov, math.hypot(tx, ty), end - start))
    return out


def main() -> None:
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    cv2.setNumThreads(1)
    scenario, seeds = sys.argv[1], [int(s) for s in sys.argv[2].split(",")]
    condition = sys.argv[3] if len(sys.argv) > 3 else "clear"
    rows = [r for seed in seeds for r in spans(scenario, seed, condition)]
    if not rows:
        sys.exit("no keyframe span was measured")
    err = np.array([r[0] for r in rows])
    var = np.array([np.diag(r[1]) for r in rows])
    length = np.array([r[2] for r in rows])
    moving = length > 0.5
    z2 = (err[:, :2] ** 2 / var[:, :2]).ravel()
    print(json.dumps({
        "scenario": scenario, "condition": condition, "seeds": seeds, "n": len(rows),
        "span_frames_median": float(np.median([r[3] for r in rows])),
        "along_std_m": float(err[:, 0].std()), "across_std_m": float(err[:, 1].std()),
        "yaw_std_rad": float(err[:, 2].std()),
        "along_rel_std": float((err[moving, 0] / length[moving]).std()) if moving.any() else None,
        "z2_median": float(np.median(z2)), "z2_p90": float(np.percentile(z2, 90)), "z2_mean": float(z2.mean())}))


if __name__ == "__main__":
    main()
