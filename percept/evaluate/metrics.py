"""The figures evaluation reads from each run JSON: its safety counts (the unsafe ones, each task's counts and
missed outcomes) and every other number, flat, with which side of each is the better one."""

from __future__ import annotations

from .resume import COUNTS, groups

UNSAFE = COUNTS
"""What makes a run fail ``--strict``: any of the run-level safety counts."""
RUN_HEADLINES = (("progress.mean_speed_mps", "mean speed [m/s]", "{:.2f}"),
                 ("progress.set_speed_ratio", "of the set speed", "{:.3f}"),
                 ("lane_changes.completed", "changes completed", "{:.2f}"),
                 ("lane_changes.aborted", "changes aborted", "{:.2f}"),
                 ("lane_changes.peak_lateral_accel_mps2", "peak lateral accel [m/s²]", "{:.2f}"),
                 ("lane_changes.peak_lateral_jerk_mps3", "peak lateral jerk [m/s³]", "{:.2f}"),
                 ("evasive.count", "evasive manoeuvres", "{:.2f}"),
                 ("evasive.collisions", "evasive, ending in a collision", "{:.2f}"))
"""The run-level figures the summaries show beside the tasks' headlines: (metric, label, format)."""


def safety_counts(tasks) -> list[tuple[str, str]]:
    """(metric, label) of every count summed per scenario x condition: the unsafe counts of every run, then each
    task's counts and the events of its outcome that did not end well."""
    out = [(k, k.replace("_", " ")) for k in UNSAFE]
    for t in tasks:
        if t.outcome is not None:
            out.append((t.outcome.missed, t.outcome.missed.replace("_", " ")))
        out += [(c.key, c.label) for c in t.counts]
    return out


def higher_is_better(tasks) -> frozenset[str]:
    """The metrics (``<group>.<key>``) where more is better: the realtime factor and those the tasks name."""
    return frozenset({"realtime_factor", "progress.mean_speed_mps", "progress.set_speed_ratio", "progress.distance_m"}
                     | {f"{t.name}.{k}" for t in tasks for k in t.higher_is_better})


def run_metrics(run: dict, tasks) -> dict[str, float]:
    """The numeric metrics of one run JSON, flat: the safety counts (``safety_counts``), ``<group>.<key>`` and
    ``realtime_factor``."""
    out: dict[str, float] = {k: float(run[k]) for k in COUNTS}
    for t in tasks:
        group = run.get(t.name) or {}
        if t.outcome is not None:
            events = group.get(t.outcome.key)
            out[t.outcome.missed] = float(sum(1 for e in events if not e)) if events else 0.0
        for c in t.counts:
            out[c.key] = float(group.get(c.key) or 0)
    for g in groups(tasks):
        for k, v in (run.get(g) or {}).items():
            if isinstance(v, (int, float)) and not isinstance(v, bool):
                out[f"{g}.{k}"] = float(v)
    if isinstance(run.get("realtime_factor"), (int, float)):
        out["realtime_factor"] = float(run["realtime_factor"])
    return out
