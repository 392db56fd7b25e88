"""Longitudinal part: the lead. Range, range rate and time to contact beside the true in-path obstacle's, with the
vision slot's separate cues (stereo and ground-contact range, the range rate from image expansion); a line across
the path at the lead's range; its box on the left image labelled with range and TTC."""

from __future__ import annotations

import rerun as rr

from ..context import TRUTH_VS_ESTIMATE, Part, PartContext, Plot, cross_line

LEAD_RGB = (255, 80, 200)
TTC_SHOWN_S = 20.0
"""Times to contact above this are left out of the plot (they would flatten it) [s]."""


def true_lead(ctx: PartContext, truth) -> tuple[float | None, float | None, float | None]:
    """The true in-path obstacle as (range [m] from the left camera, range rate [m/s], TTC [s] or None)."""
    obstacle = truth.in_path
    if obstacle is None:
        return None, None, None
    range_m = ctx.range_from_gap_m(obstacle.gap_m)
    rate = obstacle.speed_mps - truth.truth.speed_mps
    return range_m, rate, _shown(range_m / -rate if rate < 0 else None)


def _shown(ttc_s: float | None) -> float | None:
    """``ttc_s`` if the plot shows it (at most TTC_SHOWN_S), else None."""
    return ttc_s if ttc_s is not None and ttc_s <= TTC_SHOWN_S else None


def label(lead) -> str:
    """The lead's label: its range and time to contact ("opening" when the gap grows)."""
    ttc = f"TTC {lead.ttc_s:.1f} s" if lead.ttc_s is not None else "opening"
    return f"{lead.range_m:.1f} m {ttc}"


def draw(rec: rr.RecordingStream, ctx: PartContext, lead, debug, truth) -> None:
    """``lead``: Lead or None."""
    t_range, t_rate, t_ttc = true_lead(ctx, truth)
    ctx.scalars("range_m", truth=t_range, estimate=lead.range_m if lead else None)
    ctx.scalars("range_rate_mps", truth=t_rate, estimate=lead.range_rate_mps if lead else None)
    if hasattr(debug, "expansion"):  # the vision slot's cues, each before fusion
        contact, expansion = debug.contact, debug.expansion
        ctx.scalars("range_m", stereo=debug.measured_m, contact=contact.range_m if contact else None)
        ctx.scalars("range_rate_mps",
                    flow=expansion.range_rate_mps(lead.range_m) if expansion is not None and lead else None)
    ctx.scalars("ttc_s", truth=t_ttc, estimate=_shown(lead.ttc_s) if lead else None)
    if lead is None:
        ctx.buffer.clear(ctx.around_ego("lead"))
    else:
        ctx.buffer.add(ctx.around_ego("lead"), rr.LineStrips3D, strips=[cross_line(ctx.camera_x_m() + lead.range_m)],
                       colors=[LEAD_RGB], radii=[0.15], labels=[label(lead)])
    if not ctx.image:
        return
    if lead is None or lead.box_px is None:
        ctx.buffer.clear(ctx.on_image("lead"))
        return
    (u0, v0), (u1, v1) = ctx.px([lead.box_px[:2], lead.box_px[2:]])
    rec.log(ctx.on_image("lead"), rr.Boxes2D(array=[u0, v0, u1, v1], array_format=rr.Box2DFormat.XYXY,
                                             colors=[LEAD_RGB], radii=1.5, labels=[label(lead)]))


STEREO_RGB, CONTACT_RGB, FLOW_RGB = (90, 170, 255), (250, 190, 60), (120, 220, 120)
CUES = (("stereo", STEREO_RGB), ("contact", CONTACT_RGB))
PART = Part(draw, plots=(Plot("range_m", "range [m]", TRUTH_VS_ESTIMATE + CUES),
                         Plot("range_rate_mps", "range rate [m/s]", TRUTH_VS_ESTIMATE + (("flow", FLOW_RGB),)),
                         Plot("ttc_s", f"TTC [s] (to {TTC_SHOWN_S:.0f})")))
