"""`percept scenarios`: the scenarios and the conditions any of them can run in."""

from __future__ import annotations

from rich.table import Table

from . import options as opt
from .common import check_outputs, console, write_json


def scenarios(json_path: opt.JsonOut = None):
    """List the scenarios (with whether their traffic changes lanes and whether the rear rig is on by default) and the
    conditions any of them can run in."""
    from percept.sims import CONDITION_SUMMARY, SCENARIOS

    check_outputs([json_path])
    t = Table(title="scenarios")
    t.add_column("name")
    t.add_column("default duration [s]", justify="right")
    t.add_column("lane changes")
    t.add_column("rear rig")
    t.add_column("what happens")
    for s in SCENARIOS.values():
        t.add_row(s.name, f"{s.duration_s:.0f}", "yes" if s.lane_changes else "no",
                  "on" if s.rear_by_default else "off", s.summary)
    console.print(t)
    c = Table(title="conditions (--condition, any scenario)")
    c.add_column("name")
    c.add_column("what changes")
    for k, v in CONDITION_SUMMARY.items():
        c.add_row(k.value, v)
    console.print(c)
    write_json(json_path, {"scenarios": {s.name: {"summary": s.summary, "duration_s": s.duration_s,
                                                  "lane_changes": s.lane_changes, "rear": s.rear_by_default}
                                for s in SCENARIOS.values()},
                           "conditions": {k.value: v for k, v in CONDITION_SUMMARY.items()}})
