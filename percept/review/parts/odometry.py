"""Odometry part: the pose estimate. Its position error and speed beside the truth; in the world, the estimated
trail (one point per frame, shown with its whole past) and an arrow for the estimated heading."""

from __future__ import annotations

import math

import rerun as rr

from ..context import ESTIMATE_RGB, Part, PartContext, Plot

TRAIL = "world/odometry/trail"
POSE = "world/odometry/pose"
ARROW_M = 4.0


def draw(rec: rr.RecordingStream, ctx: PartContext, estimate, debug, truth) -> None:
    """``estimate``: PoseEstimate or None."""
    gt = truth.truth
    valid = estimate is not None and estimate.valid
    pose = estimate.pose if valid else None
    error = math.hypot(pose.x_m - gt.ego.x_m, pose.y_m - gt.ego.y_m) if valid else None
    ctx.scalars(rec, "position_error_m", error=error)
    ctx.scalars(rec, "speed_mps", truth=gt.speed_mps, estimate=estimate.speed_mps if estimate is not None else None)
    if pose is None:
        rec.log(POSE, rr.Clear(recursive=False))
        return
    rec.log(TRAIL, rr.Points3D([[pose.x_m, pose.y_m, 0.15]], colors=[ESTIMATE_RGB], radii=0.15))
    heading = [ARROW_M * math.cos(pose.yaw_rad), ARROW_M * math.sin(pose.yaw_rad), 0.0]
    rec.log(POSE, rr.Arrows3D(origins=[[pose.x_m, pose.y_m, 0.3]], vectors=[heading], colors=[ESTIMATE_RGB],
                              radii=0.12))


PART = Part(draw, plots=(Plot("position_error_m", "position error [m]", (("error", ESTIMATE_RGB),)),
                         Plot("speed_mps", "speed [m/s]")), trails=(TRAIL,))
