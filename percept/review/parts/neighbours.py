"""Neighbours part: every tracked vehicle around the car. Around the ego a box per track on the true ego lane
(``lane_view``), coloured by its lane (right, ego, left), fainter where no camera measured it this frame (held by
prediction), red with its time to crossing while it is flagged as cutting in, labelled with its gap and relative
speed; the blind zone beside the ego that neither rig sees (the band of centres of ``TrackerConfig``), amber while
a track is held in it. Per lane, the nearest gap and relative speed ahead and behind beside the truth's. A warning
in the event log when a cut-in starts (and a line when it ends). On each rig's left image the boxes of the tracks
that rig measured, and (vision slot) its detections this frame, thin."""

from __future__ import annotations

import numpy as np
import rerun as rr

from percept.neighbours import TrackerConfig
from percept.sensors import Neighbours, Zone

from ..context import Part, PartContext, Plot
from .lane_view import (LANE_NAMES, LANES, band_outline, lane_to_vehicle, nearest_estimates, nearest_truths,
                        true_lane)

LANE_RGB = {-1: (0, 200, 255), 0: (255, 170, 0), 1: (190, 100, 255)}
"""Colour of the tracks in the lane right of the ego (-1), in its lane (0) and left of it (+1)."""
CUT_IN_RGB = (255, 40, 40)
BLIND_RGB, BLIND_HELD_RGB = (150, 150, 150), (255, 190, 0)
DETECTION_RGB = (200, 200, 200)
PREDICTED_SHADE = 0.45
"""A predicted-only track's colour: its lane's colour times this, half transparent."""
BODY_SIZE_M = (2.0, 1.5)
"""The width and height each track is drawn with [m] (highway-env's Vehicle.WIDTH; a car's height)."""
LOG = "neighbours/warnings"
"""The text log of cut-in warnings: one line when a track's warning starts, one when it ends."""
BLIND = TrackerConfig()
"""Where the tracker holds tracks by prediction: its default blind band."""
RANGE = {"ahead_m": Neighbours.ahead_m, "behind_m": Neighbours.behind_m}
"""How far the truth's nearest vehicles are looked for without an estimate [m] (``Neighbours``' defaults)."""


def tint(rgb: tuple[int, int, int]) -> tuple[int, int, int]:
    """Halfway to white: the colour of a lane's true series."""
    return tuple((c + 255) // 2 for c in rgb)


def faint(rgb: tuple[int, int, int]) -> tuple[int, int, int, int]:
    """A predicted-only track's colour (RGBA)."""
    return (*(round(c * PREDICTED_SHADE) for c in rgb), 140)


def label(n) -> str:
    """A track's label: id, gap (or where beside), relative speed; a cut-in's time to crossing; "predicted" when no
    camera measured it this frame."""
    where = f"beside {n.x_m:+.1f} m" if n.zone is Zone.BESIDE else f"{n.gap_m:.1f} m {n.zone.value}"
    text = f"#{n.track_id} {where} {n.rel_speed_mps:+.1f} m/s"
    if n.cut_in:
        text = f"CUT-IN {n.time_to_cross_s:.1f} s | {text}" if n.time_to_cross_s is not None else f"CUT-IN | {text}"
    return text + (" (predicted)" if n.predicted else "")


def short_label(n) -> str:
    """A track's label on an image: id and gap (the lane is its colour); a cut-in's time to crossing."""
    text = f"#{n.track_id} {n.gap_m:.0f} m"
    return f"CUT-IN {n.time_to_cross_s:.1f} s {text}" if n.cut_in and n.time_to_cross_s is not None else text


def draw_tracks(ctx: PartContext, tracks, lane) -> None:
    """The tracks around the car in three entities: measured this frame, predicted only, cutting in."""
    groups = {"measured": [n for n in tracks if not n.cut_in and not n.predicted],
              "predicted": [n for n in tracks if not n.cut_in and n.predicted],
              "cut_in": [n for n in tracks if n.cut_in]}
    width, height = BODY_SIZE_M
    for name, group in groups.items():
        path = ctx.around_ego(name)
        if not group:
            ctx.buffer.clear(path)
            continue
        x = np.array([n.x_m for n in group])
        at = lane_to_vehicle(lane, x, [n.lane * lane.width_m + n.lateral_m for n in group])
        colors = [CUT_IN_RGB if n.cut_in else faint(LANE_RGB[n.lane]) if n.predicted else LANE_RGB[n.lane]
                  for n in group]
        ctx.buffer.add(path, rr.Boxes3D, centers=np.column_stack([at[:, :2], np.full(len(x), height / 2)]),
                       half_sizes=[[n.length_m / 2, width / 2, height / 2] for n in group],
                       rotation_axis_angles=[rr.RotationAxisAngle(axis=[0, 0, 1], radians=a) for a in at[:, 3]],
                       colors=[(*c, 255) if len(c) == 3 else c for c in colors],
                       radii=[0.2 if name == "cut_in" else 0.05 if name == "predicted" else 0.1],
                       labels=[label(n) for n in group])


def draw_blind_zone(ctx: PartContext, tracks, lane) -> None:
    """The blind band beside the ego in each lane beside it, amber while a predicted track is held in it."""
    w, x0, x1 = lane.width_m, BLIND.blind_behind_m, BLIND.blind_ahead_m
    strips, colors = [], []
    for side in (-1, 1):
        strips.append(band_outline(lane, x0, x1, side * w / 2, side * 3 * w / 2))
        held = any(n.lane == side and n.predicted and x0 <= n.x_m <= x1 for n in tracks)
        colors.append(BLIND_HELD_RGB if held else BLIND_RGB)
    ctx.buffer.add(ctx.around_ego("blind_zone"), rr.LineStrips3D, strips=strips, colors=colors, radii=[0.06],
                   labels=["blind zone"] * len(strips))


def plot_lanes(ctx: PartContext, neighbours, truth, lane) -> None:
    """Per lane, the nearest gap and relative speed ahead and behind: the estimate as ``right``, ``ego``, ``left``,
    the truth as ``truth_right``, ``truth_ego``, ``truth_left``."""
    reach = (RANGE if neighbours is None else {"ahead_m": neighbours.ahead_m, "behind_m": neighbours.behind_m})
    est, true = nearest_estimates(neighbours), nearest_truths(truth, lane, **reach)
    for zone in (Zone.AHEAD, Zone.BEHIND):
        for i, key in ((0, f"gap_{zone.value}_m"), (1, f"rel_speed_{zone.value}_mps")):
            series = {}
            for k in LANES:
                e, t = est.get((k, zone)), true.get((k, zone))
                series[f"truth_{LANE_NAMES[k]}"] = t[i] if t else None
                series[LANE_NAMES[k]] = e[i] if e else None
            ctx.scalars(key, **series)


def log_cut_ins(rec: rr.RecordingStream, ctx: PartContext, tracks) -> None:
    """A warning when a track is first flagged as cutting in, a line when its flag drops (or the track goes)."""
    now = {n.track_id: n for n in tracks if n.cut_in}
    before = ctx.memory.get("cut_ins", set())
    for tid in sorted(now.keys() - before):
        n = now[tid]
        side = "left" if n.lane > 0 else "right" if n.lane < 0 else "ego"
        when = f", crosses in {n.time_to_cross_s:.1f} s" if n.time_to_cross_s is not None else ""
        rec.log(LOG, rr.TextLog(f"cut-in: #{tid} from the {side} lane, {n.gap_m:.1f} m {n.zone.value}, "
                                f"{n.rel_speed_mps:+.1f} m/s{when}", level=rr.TextLogLevel.WARN))
    for tid in sorted(before - now.keys()):
        rec.log(LOG, rr.TextLog(f"cut-in over: #{tid}", level=rr.TextLogLevel.INFO))
    ctx.memory["cut_ins"] = set(now)


def boxes_2d(rec: rr.RecordingStream, ctx: PartContext, path: str, boxes, colors, labels, width: float) -> None:
    """Boxes (u0, v0, u1, v1) in camera pixels on a stored image at ``path`` (none: the entity is cleared)."""
    if not boxes:
        ctx.buffer.clear(path)
        return
    arr = [[*ctx.px([b[:2]])[0], *ctx.px([b[2:]])[0]] for b in boxes]
    rec.log(path, rr.Boxes2D(array=arr, array_format=rr.Box2DFormat.XYXY, colors=colors, radii=width,
                             labels=labels))


def draw_on_images(rec: rr.RecordingStream, ctx: PartContext, tracks, debug) -> None:
    """On each rig's left image stored this frame: the tracks it measured, and the vision slot's detections."""
    detections = getattr(debug, "detections", None) or {}
    for rig, on, stored in (("front", ctx.on_image, ctx.image), ("rear", ctx.on_rear_image, ctx.rear_image)):
        if not stored:
            continue
        seen = [n for n in tracks if n.camera == rig and n.box_px is not None]
        boxes_2d(rec, ctx, on("tracks"), [n.box_px for n in seen],
                 [CUT_IN_RGB if n.cut_in else LANE_RGB[n.lane] for n in seen], [short_label(n) for n in seen], 2.0)
        dets = detections.get(rig, [])
        boxes_2d(rec, ctx, on("detections"), [d.box_px for d in dets], [DETECTION_RGB],
                 [f"{d.x_m:.1f} m" for d in dets], 1.0)


def draw(rec: rr.RecordingStream, ctx: PartContext, neighbours, debug, truth) -> None:
    """``neighbours``: Neighbours or None; ``debug``: the vision slot's ``NeighbourDebug`` or None."""
    lane = true_lane(truth)
    tracks = [n for n in (neighbours.tracks if neighbours is not None else ()) if n.lane in LANE_RGB]
    draw_tracks(ctx, tracks, lane)
    draw_blind_zone(ctx, tracks, lane)
    plot_lanes(ctx, neighbours, truth, lane)
    log_cut_ins(rec, ctx, tracks)
    draw_on_images(rec, ctx, tracks, debug)


def lane_plot(key: str, title: str) -> Plot:
    """One plot of a quantity in every lane: each lane's truth (wide, pale) and estimate in the lane's colour."""
    series = tuple(s for k in LANES
                   for s in ((f"truth_{LANE_NAMES[k]}", tint(LANE_RGB[k])), (LANE_NAMES[k], LANE_RGB[k])))
    return Plot(key, title, series, wide=tuple(f"truth_{LANE_NAMES[k]}" for k in LANES))


PART = Part(draw, plots=(lane_plot("gap_ahead_m", "gap ahead [m] (nearest per lane)"),
                         lane_plot("gap_behind_m", "gap behind [m] (nearest per lane)"),
                         lane_plot("rel_speed_ahead_mps", "relative speed ahead [m/s]"),
                         lane_plot("rel_speed_behind_mps", "relative speed behind [m/s]")),
            texts=(LOG,))
