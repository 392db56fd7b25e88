"""Odometry part: the pose estimate. Its position error and speed beside the truth; in the world, the estimated
trail (one point per frame, shown with its whole past) and an arrow for the estimated heading. With the vision
slot (``OdometryDebug``) also the trails of visual odometry alone, dead reckoning and the fused estimate without
landmark fixes, each one's position error beside the estimate's 3-sigma bound, and every landmark fix: the sign
on the image and a line from the car to the mapped sign."""

from __future__ import annotations

import math

import numpy as np
import rerun as rr

from ..context import ESTIMATE_RGB, Part, PartContext, Plot

TRAIL = "world/odometry/trail"
POSE = "world/odometry/pose"
FIXES = "world/odometry/fixes"
ARROW_M = 4.0
VO_RGB, DR_RGB, FUSED_RGB, BOUND_RGB, FIX_RGB = (80, 200, 255), (200, 80, 200), (120, 220, 120), (150, 150, 150), \
    (255, 230, 0)
# the other trajectories of the vision slot: debug attribute, trail entity, colour
OTHERS = (("vo_pose", "world/odometry/vo_trail", VO_RGB), ("dead_reckoning_pose", "world/odometry/dr_trail", DR_RGB),
          ("fused_pose", "world/odometry/fused_trail", FUSED_RGB))


def _error(pose, gt) -> float:
    """Distance from ``pose`` to the true ego position [m]."""
    return math.hypot(pose.x_m - gt.ego.x_m, pose.y_m - gt.ego.y_m)


def draw(rec: rr.RecordingStream, ctx: PartContext, estimate, debug, truth) -> None:
    """``estimate``: PoseEstimate or None; ``debug``: OdometryDebug (vision) or None (privileged)."""
    gt = truth.truth
    valid = estimate is not None and estimate.valid
    pose = estimate.pose if valid else None
    # 3 sigma of the position along its worst direction: 3 sqrt(largest eigenvalue of the xy covariance)
    bound = 3.0 * math.sqrt(max(np.linalg.eigvalsh(estimate.covariance[:2, :2])[-1], 0.0)) if valid else None
    ctx.scalars("position_error_m", error=_error(pose, gt) if valid else None, bound_3sigma=bound,
                **{name: _error(getattr(debug, attr), gt) if debug is not None else None
                   for attr, name in (("fused_pose", "fused"), ("vo_pose", "vo"), ("dead_reckoning_pose", "dr"))})
    ctx.scalars("speed_mps", truth=gt.speed_mps, estimate=estimate.speed_mps if estimate is not None else None)
    if pose is None:
        ctx.buffer.clear(POSE)
        return
    ctx.buffer.add(TRAIL, rr.Points3D, positions=[[pose.x_m, pose.y_m, 0.15]], colors=[ESTIMATE_RGB], radii=[0.15])
    heading = [ARROW_M * math.cos(pose.yaw_rad), ARROW_M * math.sin(pose.yaw_rad), 0.0]
    ctx.buffer.add(POSE, rr.Arrows3D, origins=[[pose.x_m, pose.y_m, 0.3]], vectors=[heading], colors=[ESTIMATE_RGB],
                   radii=[0.12])
    if debug is not None:
        _draw_vision(rec, ctx, pose, debug)


def _draw_vision(rec: rr.RecordingStream, ctx: PartContext, pose, debug) -> None:
    """The vision slot's other trails and this frame's landmark fixes."""
    for attr, path, rgb in OTHERS:
        p = getattr(debug, attr)
        ctx.buffer.add(path, rr.Points3D, positions=[[p.x_m, p.y_m, 0.1]], colors=[rgb], radii=[0.1])
    if not debug.sightings:
        ctx.buffer.clear(FIXES)
        if ctx.image:
            ctx.buffer.clear(ctx.on_image("signs"))
        return
    world = pose.world_from_vehicle()
    ends = [world.apply(s.position_v_m) for s in debug.sightings]
    rec.log(FIXES, rr.LineStrips3D([[[pose.x_m, pose.y_m, 1.0], list(e)] for e in ends], colors=[FIX_RGB],
                                   radii=0.05, labels=[f"sign {s.marker_id}, {s.range_m:.1f} m"
                                                       for s in debug.sightings]))
    if ctx.image:
        rec.log(ctx.on_image("signs"), rr.LineStrips2D([ctx.px(np.vstack([s.corners_px, s.corners_px[:1]]))
                                                        for s in debug.sightings], colors=[FIX_RGB],
                                                       labels=[f"{s.marker_id}" for s in debug.sightings]))


PART = Part(draw, plots=(Plot("position_error_m", "position error [m]",
                              (("error", ESTIMATE_RGB), ("bound_3sigma", BOUND_RGB), ("fused", FUSED_RGB),
                               ("vo", VO_RGB), ("dr", DR_RGB))),
                         Plot("speed_mps", "speed [m/s]")), trails=(TRAIL,) + tuple(p for _, p, _ in OTHERS))
