"""Lanes part: the ego path. Offset, heading and curvature of the estimate beside the true lane; the path
around the car; its boundaries on the left image and, from the vision slot's ``LaneDebug``, the marking
evidence (coloured by the side the fit gave it)."""

from __future__ import annotations

import numpy as np
import rerun as rr

from percept.lanes.realworld import boundary_points_px

from ..context import Part, PartContext, Plot

SIDE_RGB = {1: (255, 220, 0), -1: (0, 160, 255), 0: (150, 150, 150)}
"""Lane boundaries and their evidence: left, right, unassigned (RGB)."""
PATH_RGB = (60, 220, 90)
DRAW_M = (4.0, 50.0)
"""Range ahead over which the path and its boundaries are drawn [m]."""
POINTS = 12
"""Points per drawn curve (the curves are cubics: a dozen points draw them smoothly)."""
KEYS = ("offset_m", "heading_rad", "curvature_1pm")


def draw(rec: rr.RecordingStream, ctx: PartContext, path, debug, truth) -> None:
    """``path``: EgoPath or None; ``debug``: LaneDebug (vision) or None."""
    lane = path.lane if path is not None and path.follows_lane else None
    for key in KEYS:
        ctx.scalars(key, truth=getattr(truth.truth.lane, key), estimate=getattr(lane, key, None))
    ctx.scalars("confidence", estimate=path.lane.confidence if path is not None and path.lane else None)
    _draw_path(rec, ctx, path, lane)
    if ctx.image:
        _draw_on_image(rec, ctx, lane, debug)


def _draw_path(rec: rr.RecordingStream, ctx: PartContext, path, lane) -> None:
    """The centre of the path (green) and the lane boundaries (left yellow, right blue) on the ground."""
    if path is None:
        ctx.buffer.clear(ctx.around_ego("path"))
        return
    x = np.linspace(*DRAW_M, POINTS)
    strips = [np.column_stack([x, path.centre_y(x), np.zeros_like(x)])]
    colors = [PATH_RGB]
    if lane is not None:
        ground = lane.boundary_points_m(*DRAW_M, n=POINTS)
        strips += [ground["left"], ground["right"]]
        colors += [SIDE_RGB[1], SIDE_RGB[-1]]
    ctx.buffer.add(ctx.around_ego("path"), rr.LineStrips3D, strips=strips, colors=colors, radii=[0.1])


def _draw_on_image(rec: rr.RecordingStream, ctx: PartContext, lane, debug) -> None:
    """The lane boundaries and the vision slot's marking evidence on the left image."""
    if lane is not None:
        px = boundary_points_px(ctx.rig, lane, *DRAW_M, n=POINTS)
        rec.log(ctx.on_image("boundaries"), rr.LineStrips2D([ctx.px(px["left"]), ctx.px(px["right"])],
                                                            colors=[SIDE_RGB[1], SIDE_RGB[-1]], radii=1.5))
    else:
        ctx.buffer.clear(ctx.on_image("boundaries"))
    evidence = getattr(debug, "evidence", None)
    if evidence is None or not len(evidence.uv_px):
        if debug is not None:
            ctx.buffer.clear(ctx.on_image("evidence"))
        return
    fit = getattr(debug, "fit", None)
    side = fit.side if fit is not None else np.zeros(len(evidence.uv_px), int)
    # side +1 -> class 1, -1 -> class 2, 0 -> class 0 (the annotation context logged by ``style``)
    rec.log(ctx.on_image("evidence"), rr.Points2D(ctx.px(evidence.uv_px).astype(np.float32),
                                                  class_ids=(np.asarray(side) % 3).astype(np.uint16)))


def style(rec: rr.RecordingStream, ctx: PartContext) -> None:
    """The evidence classes (static): colours by side, small points."""
    rec.log(ctx.on_image("evidence"), rr.AnnotationContext([(0, "outlier", SIDE_RGB[0]), (1, "left", SIDE_RGB[1]),
                                                            (2, "right", SIDE_RGB[-1])]), static=True)
    rec.log(ctx.on_image("evidence"), rr.Points2D.from_fields(radii=[1.0]), static=True)


PART = Part(draw, setup=style, plots=(Plot("offset_m", "offset [m]"), Plot("heading_rad", "heading [rad]"),
                         Plot("curvature_1pm", "curvature [1/m]")))
