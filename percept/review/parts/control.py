"""Control part (drawn for every run, not a task): speed, the commanded acceleration beside the terms it was
chosen from, the steering command, a log line whenever the law term that limits a command changes, and the lane
changes: each start, end and return in the log with MOBIL's reason, the planned path on the ground and on the left
image."""

from __future__ import annotations

import numpy as np
import rerun as rr

from percept.control import EVASIVE_EVENTS
from percept.sensors import EgoPath
from percept.sensors.vehicle import ACCEL_RANGE_MPS2

from ..context import ESTIMATE_RGB, TRUTH_RGB, Part, PartContext, Plot, log_on_change

LOG = "control/limits"
CHANGES = "control/lane_changes"
PLAN_RGB = (255, 140, 0)
"""A lane change's planned path (RGB)."""
TERM_RGB = {"cruise": (150, 150, 150), "follow": (80, 160, 255), "yield": (220, 90, 255),
            "emergency": (255, 40, 40), "hold": (160, 30, 30), "commitment": (170, 110, 255)}
"""The acceleration terms of the following and emergency-braking laws (RGB)."""


def limits(control: dict) -> tuple[str, str]:
    """Which term set the acceleration and the steering (from the laws' debug records)."""
    braking, following = control.get("emergency_braking"), control.get("following")
    accel = getattr(braking, "limited_by", "?")
    if accel == "follow" and following is not None:
        accel = following.limited_by  # the following law's own choice: cruise or follow
    return accel, getattr(control.get("lane_keeping"), "limited_by", "?")


def draw(rec: rr.RecordingStream, ctx: PartContext, step, control: dict, truth) -> None:
    """``step``: the AgentStep; ``control``: its laws' debug records by law name."""
    ctx.scalars("speed_mps", truth=truth.truth.speed_mps)
    following, braking = control.get("following"), control.get("emergency_braking")
    terms = dict(getattr(braking, "terms", None) or {})
    terms.pop("follow", None)  # the following law's output: shown as its own two terms
    terms["cruise"] = getattr(following, "cruise_mps2", None)
    terms["follow"] = getattr(following, "follow_mps2", None)
    # a term beyond what a law may command is drawn at the limit (the log says the limit clipped it): an emergency
    # term of -1000 m/s² just before contact would flatten the plot
    ctx.scalars("accel_mps2", command=step.accel_mps2,
                **{k: None if terms.get(k) is None else float(np.clip(terms[k], *ACCEL_RANGE_MPS2)) for k in TERM_RGB})
    ctx.scalars("steering_rad", command=step.steering_rad)
    accel, steering = limits(control)
    log_on_change(rec, ctx, LOG, (accel, steering), f"acceleration limited by {accel}; steering: {steering}")
    change = control.get("lane_change")
    if change is not None:
        _draw_change(rec, ctx, change, next((e for e in step.estimates.values() if isinstance(e, EgoPath)), None))


def _draw_change(rec: rr.RecordingStream, ctx: PartContext, change, path: EgoPath | None) -> None:
    """A lane change's events in the log and its planned path around the car and on the left image."""
    if change.event is not None:
        where = {1: "to the left", -1: "to the right"}.get(change.side, "")
        level = rr.TextLogLevel.INFO if change.event in ("started", "completed") else rr.TextLogLevel.WARN
        ev = change.evasion
        text = (f"evasive {change.event} {where}: braking needs {ev.needed_mps2:.1f} m/s²"
                if ev is not None and change.event in EVASIVE_EVENTS
                else f"lane change {where} {change.event}: {change.reason}")
        rec.log(CHANGES, rr.TextLog(text.replace("  ", " "), level=level))
    lane = path.lane if path is not None and path.follows_lane else None
    if not change.plan_m or lane is None:
        ctx.buffer.clear(ctx.around_ego("lane_change"))
        if ctx.image:
            ctx.buffer.clear(ctx.on_image("lane_change"))
        return
    ahead, offset = (np.array(v) for v in zip(*change.plan_m))
    # a point offset r from the lane's centre at x ahead: y = y_c(x) + r
    ground = np.column_stack([ahead, lane.centre_y(ahead) + offset, np.zeros_like(ahead)])
    ctx.buffer.add(ctx.around_ego("lane_change"), rr.LineStrips3D, strips=[ground], colors=[PLAN_RGB], radii=[0.15])
    if ctx.image:
        uv, z = ctx.rig.project_vehicle_points(ground)
        rec.log(ctx.on_image("lane_change"), rr.LineStrips2D([ctx.px(uv[z > 0.1])], colors=[PLAN_RGB], radii=2.0))


PART = Part(draw, plots=(Plot("speed_mps", "speed [m/s]", (("truth", TRUTH_RGB),)),
                         Plot("accel_mps2", "accel [m/s²]",
                              (("command", ESTIMATE_RGB), *TERM_RGB.items())),
                         Plot("steering_rad", "steering [rad]", (("command", ESTIMATE_RGB),))), texts=(LOG, CHANGES))
