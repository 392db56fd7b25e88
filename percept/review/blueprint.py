"""The layout a recording opens with: the left camera (with a rear rig, the rear camera beside it), a 3D view that
follows the ego and an event log (control limits, braking requests, cut-in warnings) in one column, beside the
time-series views of each task (estimate beside truth, in the task's units) and of the control."""

from __future__ import annotations

import rerun.blueprint as rrb

from .context import CAMERA, EGO, REAR_CAMERA, TIMELINE, Part

TRAJECTORY = "world/trajectory"
ROW_VIEWS = 3
"""Views per row of plots: a task's views stay together (more than this: in rows of equal length); tasks with few
views share a row."""
CHASE_EYE = dict(position=(-13.0, 0.0, 6.0), look_target=(30.0, 0.0, 0.0), eye_up=(0.0, 0.0, 1.0))
"""The 3D eye behind and above the ego, in its vehicle frame [m]."""
REAR_EYE = dict(position=(-40.0, 0.0, 26.0), look_target=(15.0, 0.0, 0.0), eye_up=(0.0, 0.0, 1.0))
"""The 3D eye with a rear rig: further back and higher, so that what the rear rig sees behind the ego is in view
too [m]."""


def past_and_present() -> rrb.VisibleTimeRanges:
    """Everything logged up to the time cursor (a trail of one point per frame)."""
    return rrb.VisibleTimeRanges(timeline=TIMELINE, start=rrb.TimeRangeBoundary.infinite(),
                                 end=rrb.TimeRangeBoundary.cursor_relative())


def world_view(trails: list[str], eye: dict = CHASE_EYE) -> rrb.Spatial3DView:
    """The 3D scene in the ego's frame (so it follows the car), seen from behind and above (``eye``); ``trails``
    keep their whole past. The camera images are left to their own views."""
    return rrb.Spatial3DView(
        name="3D (follows the ego)", origin=EGO, contents=["+ /world/**", f"- /{CAMERA}/**", f"- /{REAR_CAMERA}/**"],
        eye_controls=rrb.EyeControls3D(kind=rrb.Eye3DKind.Orbital, **eye),
        overrides={path: past_and_present() for path in trails},
    )


def task_views(name: str, part) -> list[rrb.View]:
    """One task's time-series views (a plain callable part: one view of everything under ``<name>/``)."""
    if not isinstance(part, Part) or not part.plots:
        return [rrb.TimeSeriesView(name=name, origin=name)]
    return [rrb.TimeSeriesView(name=f"{name}: {p.title}", origin=f"{name}/{p.key}") for p in part.plots]


def pack_rows(groups: list[list[rrb.View]]) -> list[rrb.Horizontal]:
    """Rows of at most ROW_VIEWS views, keeping each group in one row, or a longer group in rows of its own of equal
    length (four views: two rows of two)."""
    rows: list[list[rrb.View]] = []
    for views in groups:
        if rows and len(rows[-1]) + len(views) <= ROW_VIEWS:
            rows[-1].extend(views)
        else:
            n = -(-len(views) // ROW_VIEWS)  # rows it needs
            size = -(-len(views) // n)
            rows += [list(views[i:i + size]) for i in range(0, len(views), size)]
    return [rrb.Horizontal(*row) for row in rows]


def blueprint(parts: list[tuple[str, object]], rear: bool = False) -> rrb.Blueprint:
    """``parts``: (name, part) in the order their plots are laid out (the tasks, then the control); ``rear``: the
    recording has a rear camera (a view of its own beside the left camera's, and the 3D eye further back)."""
    described = [p for _, p in parts if isinstance(p, Part)]
    trails = [TRAJECTORY] + [t for p in described for t in p.trails]
    texts = [t for p in described for t in p.texts]
    camera = rrb.Spatial2DView(name="left camera", origin=CAMERA)
    if rear:
        left, shares = [rrb.Horizontal(camera, rrb.Spatial2DView(name="rear camera", origin=REAR_CAMERA)),
                        world_view(trails, REAR_EYE)], [3.0, 5.0]
    else:
        left, shares = [camera, world_view(trails)], [4.0, 4.0]
    if texts:
        left.append(rrb.TextLogView(name="events", origin="/", contents=texts,
                                    columns=rrb.TextLogColumns(text_log_columns=["Body"])))
        shares.append(1.5 if rear else 1.0)  # with a rear rig, room for cut-in warnings
    return rrb.Blueprint(
        rrb.Horizontal(
            rrb.Vertical(*left, row_shares=shares),
            rrb.Vertical(*pack_rows([task_views(name, part) for name, part in parts])),
            column_shares=[2, 3],
        ),
        rrb.BlueprintPanel(state="collapsed"), rrb.SelectionPanel(state="collapsed"),
        rrb.TimePanel(state="collapsed", timeline=TIMELINE),
    )
