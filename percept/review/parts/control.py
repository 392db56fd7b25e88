"""Control part (drawn for every run, not a task): speed, the commanded acceleration beside the terms it was
chosen from, the steering command, and a log line whenever the law term that limits a command changes."""

from __future__ import annotations

import rerun as rr

from ..context import ESTIMATE_RGB, TRUTH_RGB, Part, PartContext, Plot, log_on_change

LOG = "control/limits"
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
    ctx.scalars("accel_mps2", command=step.accel_mps2, **{k: terms.get(k) for k in TERM_RGB})
    ctx.scalars("steering_rad", command=step.steering_rad)
    accel, steering = limits(control)
    log_on_change(rec, ctx, LOG, (accel, steering), f"acceleration limited by {accel}; steering: {steering}")


PART = Part(draw, plots=(Plot("speed_mps", "speed [m/s]", (("truth", TRUTH_RGB),)),
                         Plot("accel_mps2", "accel [m/s²]",
                              (("command", ESTIMATE_RGB), *TERM_RGB.items())),
                         Plot("steering_rad", "steering [rad]", (("command", ESTIMATE_RGB),))), texts=(LOG,))
