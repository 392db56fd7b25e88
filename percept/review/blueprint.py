"""The layout a recording opens with: the left camera (and, with a rear rig, the rear camera), a 3D view that
follows the ego and an event log (control limits, braking requests, cut-in warnings) in one column, beside the
time-series views of each task (estimate beside truth, in the task's units) and of the control."""

from __future__ import annotations

import rerun.blueprint as rrb

from .context import CAMERA, EGO, REAR_CAMERA, TIMELINE, Part

TRAJECTORY = "world/trajectory"
ROW_VIEWS = 3
"""Views per row of plots: a task's views stay together; tasks with few views share a row."""
CHASE_EYE = dict(position=(-13.0, 0.0, 6.0), look_target=(30.0, 0.0, 0.0), eye_up=(0.0, 0.0, 1.0))
"""The 3D eye behind and above the ego, in its vehicle frame [m]."""


def past_and_present() -> rrb.VisibleTimeRanges:
    """Everything logged up to the time cursor (a trail of one point per frame)."""
    return rrb.VisibleTimeRanges(timeline=TIMELINE, start=rrb.TimeRangeBoundary.infinite(),
                                 end=rrb.TimeRangeBoundary.cursor_relative())


def world_view(trails: list[str]) -> rrb.Spatial3DView:
    """The 3D scene in the ego's frame (so it follows the car), seen from behind and above; ``trails`` keep their
    whole past. The camera images are left to their own views."""
    return rrb.Spatial3DView(
        name="3D (follows the ego)", origin=EGO, contents=["+ /world/**", f"- /{CAMERA}/**", f"- /{REAR_CAMERA}/**"],
        eye_controls=rrb.EyeControls3D(kind=rrb.Eye3DKind.Orbital, **CHASE_EYE),
        overrides={path: past_and_present() for path in trails},
    )


def task_views(name: str, part) -> list[rrb.View]:
    """One task's time-series views (a plain callable part: one view of everything under ``<name>/``)."""
    if not isinstance(part, Part) or not part.plots:
        return [rrb.TimeSeriesView(name=name, origin=name)]
    return [rrb.TimeSeriesView(name=f"{name}: {p.title}", origin=f"{name}/{p.key}") for p in part.plots]


def pack_rows(groups: list[list[rrb.View]]) -> list[rrb.Horizontal]:
    """Rows of at most ROW_VIEWS views, keeping each group in one row."""
    rows: list[list[rrb.View]] = []
    for views in groups:
        if rows and len(rows[-1]) + len(views) <= ROW_VIEWS:
            rows[-1].extend(views)
        else:
            rows.append(list(views))
    return [rrb.Horizontal(*row) for row in rows]


def blueprint(parts: list[tuple[str, object]], rear: bool = False) -> rrb.Blueprint:
    """``parts``: (name, part) in the order their plots are laid out (the tasks, then the control); ``rear``: the
    recording has a rear camera (a view of its own below the left camera's)."""
    described = [p for _, p in parts if isinstance(p, Part)]
    trails = [TRAJECTORY] + [t for p in described for t in p.trails]
    texts = [t for p in described for t in p.texts]
    left, shares = [rrb.Spatial2DView(name="left camera", origin=CAMERA)], [4]
    if rear:
        left.append(rrb.Spatial2DView(name="rear camera", origin=REAR_CAMERA))
        shares.append(3)
    left.append(world_view(trails))
    shares.append(4)
    if texts:
        left.append(rrb.TextLogView(name="events", origin="/", contents=texts,
                                    columns=rrb.TextLogColumns(text_log_columns=["Body"])))
        shares.append(1)
    return rrb.Blueprint(
        rrb.Horizontal(
            rrb.Vertical(*left, row_shares=shares),
            rrb.Vertical(*pack_rows([task_views(name, part) for name, part in parts])),
            column_shares=[2, 3],
        ),
        rrb.BlueprintPanel(state="collapsed"), rrb.SelectionPanel(state="collapsed"),
        rrb.TimePanel(state="collapsed", timeline=TIMELINE),
    )
