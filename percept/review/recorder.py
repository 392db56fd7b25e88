"""Rerun recording of a drive: calibration, camera image, 3D world, ego trajectory and time series.

Timeline ``sim_time`` in simulation seconds. Entities: ``world/road`` (lane lines, static), ``world/ego``
(pose), ``world/ego/camera/left`` (mount and pinhole, static; the JPEG image), ``world/objects`` (true 3D
boxes), ``world/trajectory``, and ``plots/*`` scalars. With the vision lateral slot also what the lanes module
saw: ``world/ego/camera/left/lanes`` (fitted boundaries in the image), ``.../evidence`` (marking points by
side), ``world/ego/lanes`` (the boundaries on the ground) and ``plots/lane/*/{truth,vision}``. The file is
written to a temporary name and moved into place when the recording closes, so a failed run never leaves a
truncated file under the final name.
"""

from __future__ import annotations

import os
from pathlib import Path

import cv2
import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from percept.lanes.realworld import boundary_points_px
from percept.sensors import Side, StereoRig

KIND_COLORS = {"vehicle": (70, 130, 230), "pedestrian": (240, 80, 60), "landmark": (250, 220, 60)}
SIDE_COLORS = {1: (255, 220, 0), -1: (0, 160, 255), 0: (150, 150, 150)}
"""Lane boundaries and their evidence: left, right, unassigned (RGB)."""
LANE_DRAW_M = (4.0, 50.0)
"""Range ahead over which fitted boundaries are drawn [m]."""


def blueprint() -> rrb.Blueprint:
    return rrb.Blueprint(
        rrb.Horizontal(
            rrb.Vertical(rrb.Spatial2DView(name="left camera", origin="world/ego/camera/left"),
                         rrb.TimeSeriesView(name="signals", origin="plots")),
            rrb.Spatial3DView(name="world", origin="world"),
            column_shares=[3, 2],
        ),
        collapse_panels=True,
    )


class RunRecorder:
    """Logs one run. ``log_step`` per frame; ``close`` finalises the file."""

    def __init__(self, path: Path, rig: StereoRig, lane_lines: list[np.ndarray], app_id: str = "percept",
                 jpeg_quality: int = 70):
        self.path = Path(path)
        self.tmp = self.path.with_name(self.path.name + ".part")
        self.rec = rr.RecordingStream(app_id)
        self.rec.save(str(self.tmp), default_blueprint=blueprint())
        self.quality = jpeg_quality
        self.rig = rig
        self.trajectory: list[list[float]] = []
        rec = self.rec
        rec.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
        strips = [np.column_stack([p, np.zeros(len(p))]) for p in lane_lines]
        rec.log("world/road", rr.LineStrips3D(strips, colors=[(200, 200, 200)], radii=0.08), static=True)
        cam = rig.camera
        # camera mount: vehicle_from_camera rotation is the transpose of cam_from_vehicle
        R = rig.rotation_cam_from_vehicle().T
        rec.log("world/ego/camera/left", rr.Transform3D(translation=rig.camera_position(Side.LEFT), mat3x3=R),
                static=True)
        rec.log("world/ego/camera/left", rr.Pinhole(focal_length=[cam.fx, cam.fy], principal_point=[cam.cx, cam.cy],
                                                    resolution=[cam.width, cam.height],
                                                    camera_xyz=rr.ViewCoordinates.RDF), static=True)

    def log_step(self, t_s: float, frame, gt, action: np.ndarray, lead_gap_m: float | None) -> None:
        rec = self.rec
        rec.set_time("sim_time", duration=t_s)
        e = gt.ego
        rec.log("world/ego", rr.Transform3D(translation=[e.x_m, e.y_m, 0.0],
                                            rotation=rr.RotationAxisAngle(axis=[0, 0, 1], radians=e.yaw_rad)))
        if frame.left is not None:
            ok, jpg = cv2.imencode(".jpg", frame.left, [cv2.IMWRITE_JPEG_QUALITY, self.quality])
            if ok:
                rec.log("world/ego/camera/left", rr.EncodedImage(contents=jpg.tobytes(), media_type="image/jpeg"))
        if gt.objects:
            c, s = np.cos(e.yaw_rad), np.sin(e.yaw_rad)
            centers, sizes, quats, colors, labels = [], [], [], [], []
            for o in gt.objects:
                x, y, z = o.position_m
                centers.append([e.x_m + c * x - s * y, e.y_m + s * x + c * y, z])
                sizes.append(list(o.size_m))
                yaw = e.yaw_rad + o.yaw_rad
                quats.append([0.0, 0.0, np.sin(yaw / 2), np.cos(yaw / 2)])
                colors.append(KIND_COLORS.get(o.kind, (200, 200, 200)))
                labels.append(f"{o.kind} {o.obj_id}")
            rec.log("world/objects", rr.Boxes3D(centers=centers, sizes=sizes, quaternions=quats, colors=colors,
                                                labels=labels))
        else:
            rec.log("world/objects", rr.Clear(recursive=False))
        self.trajectory.append([e.x_m, e.y_m, 0.05])
        if len(self.trajectory) % 5 == 1:
            rec.log("world/trajectory", rr.LineStrips3D([self.trajectory], colors=[(60, 220, 90)], radii=0.15))
        rec.log("plots/speed_mps", rr.Scalars(gt.speed_mps))
        rec.log("plots/accel_cmd_mps2", rr.Scalars(float(action[0])))
        rec.log("plots/steering_rad", rr.Scalars(float(action[1])))
        for name in ("offset_m", "heading_rad", "curvature_1pm"):
            rec.log(f"plots/lane/{name}/truth", rr.Scalars(getattr(gt.lane, name)))
        if lead_gap_m is not None:
            rec.log("plots/lead_gap_m", rr.Scalars(lead_gap_m))

    def log_lanes(self, est, debug) -> None:
        """What the lanes module made of this frame (call after ``log_step``): ``est`` a LaneEstimate, ``debug`` a
        LaneDebug (evidence None for a dropped frame, fit None when evidence was too thin)."""
        rec = self.rec
        cam = "world/ego/camera/left"
        ev, fit = debug.evidence, debug.fit
        if ev is not None and len(ev.uv_px):
            side = fit.side if fit is not None else np.zeros(len(ev.uv_px), int)
            colors = np.where(side[:, None] == 1, SIDE_COLORS[1], np.where(side[:, None] == -1, SIDE_COLORS[-1],
                                                                              SIDE_COLORS[0]))
            rec.log(f"{cam}/evidence", rr.Points2D(ev.uv_px, colors=colors, radii=1.5))
        else:
            rec.log(f"{cam}/evidence", rr.Clear(recursive=False))
        if est.valid:
            ground = est.boundary_points_m(*LANE_DRAW_M, n=30)
            px = boundary_points_px(self.rig, est, *LANE_DRAW_M, n=30)
            colors = [SIDE_COLORS[1], SIDE_COLORS[-1]]
            rec.log("world/ego/lanes", rr.LineStrips3D([ground["left"], ground["right"]], colors=colors, radii=0.1))
            rec.log(f"{cam}/lanes", rr.LineStrips2D([px["left"], px["right"]], colors=colors, radii=2.0))
            for name, value in (("offset_m", est.offset_m), ("heading_rad", est.heading_rad),
                                ("curvature_1pm", est.curvature_1pm)):
                rec.log(f"plots/lane/{name}/vision", rr.Scalars(value))
        else:
            rec.log("world/ego/lanes", rr.Clear(recursive=False))
            rec.log(f"{cam}/lanes", rr.Clear(recursive=False))
        rec.log("plots/lane/confidence", rr.Scalars(est.confidence))

    def close(self) -> Path:
        """Flush and move the recording to its final name."""
        if self.trajectory:
            self.rec.log("world/trajectory", rr.LineStrips3D([self.trajectory], colors=[(60, 220, 90)], radii=0.15))
        self.rec.flush()
        self.rec.disconnect()
        os.replace(self.tmp, self.path)
        return self.path
