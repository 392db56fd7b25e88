"""Pedestrians part: the braking request. Its stop-before distance beside the true in-path pedestrian's range, a
log line when a request starts, changes reason or ends, and the stop line around the car and on the image. With
the vision slot: this frame's detections (thin, with their scores) and the tracked people (id, range, lateral
speed) on the image, and the tracks on the ground around the car."""

from __future__ import annotations

import rerun as rr

from percept.sensors import BrakingRequest, ObjectKind

from ..context import Part, PartContext, Plot, cross_line, log_on_change

STOP_RGB = (240, 50, 50)
LOG = "pedestrians/requests"
"""The text log of braking requests: one line when a request starts, changes reason or ends."""
DETECTION_RGB, TRACK_RGB = (160, 160, 255), (60, 220, 255)


def draw_people(rec: rr.RecordingStream, ctx: PartContext, debug) -> None:
    """The vision slot's detections and seen tracks (``PedestrianDebug``)."""
    from percept.detection import person_box

    tracks = debug.reported
    pts = [[t.position_m[0], t.position_m[1], 0.0] for t in tracks]
    # a track whose detections move like a vehicle's is labelled with its free speed over the ground
    labels = [f"#{t.track_id} {t.position_m[0] - ctx.camera_x_m():.1f} m, {t.velocity_mps[1]:+.1f} m/s"
              + (f", moves at {t.free_speed_mps:.0f} m/s: no person" if t.too_fast else "") for t in tracks]
    ctx.buffer.add(ctx.around_ego("people"), rr.Points3D, positions=pts, colors=[TRACK_RGB], radii=[0.3],
                   labels=labels)
    if not ctx.image:
        return
    dets = [person_box(d.box_px) for d in debug.detections]
    for name, boxes, rgb, width, text in (("detections", dets, DETECTION_RGB, 1.0,
                                           [f"{d.score:.2f}" for d in debug.detections]),
                                          ("people", [t.box_px for t in tracks], TRACK_RGB, 2.0, labels)):
        arr = [[*ctx.px([b[:2]])[0], *ctx.px([b[2:]])[0]] for b in boxes]
        rec.log(ctx.on_image(name), rr.Boxes2D(array=arr, array_format=rr.Box2DFormat.XYXY, colors=[rgb],
                                               radii=width, labels=text))


def draw(rec: rr.RecordingStream, ctx: PartContext, request, debug, truth) -> None:
    """``request``: BrakingRequest or None; ``debug``: the vision slot's ``PedestrianDebug`` or None."""
    if debug is not None and hasattr(debug, "reported"):
        draw_people(rec, ctx, debug)
    obstacle = truth.in_path
    true_m = (ctx.range_from_gap_m(obstacle.gap_m)
              if obstacle is not None and obstacle.kind is ObjectKind.PEDESTRIAN else None)
    asked = BrakingRequest.asking(request) is not None
    ctx.scalars("stop_before_m", truth=true_m, estimate=request.stop_before_m if asked else None)
    if not asked:
        log_on_change(rec, ctx, LOG, None if request is None else "withdrawn",
                      "braking request ended" if request is None else f"braking request withdrawn: {request.reason}")
        ctx.buffer.clear(ctx.around_ego("stop"))
        if ctx.image:
            ctx.buffer.clear(ctx.on_image("stop"))
        return
    text = f"{request.reason}: stop before {request.stop_before_m:.1f} m"
    log_on_change(rec, ctx, LOG, request.reason, text, level=rr.TextLogLevel.WARN)
    line = cross_line(ctx.camera_x_m() + request.stop_before_m, n=9)
    rec.log(ctx.around_ego("stop"), rr.LineStrips3D([line], colors=[STOP_RGB], radii=0.15, labels=[text]))
    if ctx.image:
        uv, z = ctx.rig.project_vehicle_points(line)
        if (z > 0.1).sum() >= 2:
            rec.log(ctx.on_image("stop"), rr.LineStrips2D([ctx.px(uv[z > 0.1])], colors=[STOP_RGB], radii=2.0,
                                                          labels=[text]))
        else:
            ctx.buffer.clear(ctx.on_image("stop"))


PART = Part(draw, plots=(Plot("stop_before_m", "stop before [m]"),), texts=(LOG,))
