"""Resuming a batch: which run files in ``OUT/runs`` can be reused, which are damaged, which were made otherwise.

A run file is reused only if it is a finished run of the same job (scenario, condition, seed) made with the same
``settings``: everything else that changes a result (percept version, duration, slot sources, rendering, world
options). Damaged files (truncated, empty, not JSON, not a percept run, a run of another job) are redone; runs
made with other settings are refused before any work unless the caller redoes them.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from percept.drive import tasks as tasks_module
from percept.drive.scoring import SAFETY_COUNTS as COUNTS

if TYPE_CHECKING:
    from .plan import EvalPlan, Job


def groups(tasks=None) -> tuple[str, ...]:
    """Metric groups every run JSON has (objects): one per task (of the slot table unless given), ``timing_ms``,
    ``progress`` and ``lane_changes``."""
    return tuple(t.name for t in (tasks or tasks_module.TASKS)) + ("timing_ms", "progress", "lane_changes")


def run_settings(plan: EvalPlan) -> dict:
    """Everything besides the scenario, condition and seed that changes a run's result (a JSON object; two runs
    are comparable only if theirs are equal): percept version, duration, slot sources, rendering, world options, the
    rear rig option (None: each scenario's default; a run file without it was made so), lane changes on or off."""
    from importlib.metadata import version

    cfg = plan.config(plan.jobs[0])
    return {"percept": version("percept"), "duration_s": plan.duration_s,
            "slots": {name: src.value for name, src in cfg.sources.items()}, "render": cfg.needs_cameras,
            "detector": cfg.detector if cfg.uses_detector else None,
            "world": {"rig": cfg.world.rig.to_dict(), "scenery": cfg.world.scenery,
                      "autopilot": cfg.world.autopilot}, "rear": plan.rear, "lane_changes": plan.lane_changes,
            "ego": plan.ego}


def differences(now: dict, then) -> list[str]:
    """How the settings ``then`` of a stored run differ from ``now``: 'slots lanes=vision (now privileged)'."""
    if not isinstance(then, dict):
        return ["no settings recorded (made by an older percept)"]
    diff = []
    for k, v in now.items():
        old = then.get(k)
        if isinstance(v, dict) and isinstance(old, dict):
            diff += [f"{k} {n}={old.get(n)} (now {x})" for n, x in v.items() if old.get(n) != x]
        elif old != v:
            diff.append(f"{k} {'default' if old is None else old} (now {'default' if v is None else v})")
    return diff


def run_path(out_dir: Path, job: Job) -> Path:
    """Where the run JSON of ``job`` goes: ``OUT/runs/<scenario>-<condition>-<seed>.json``."""
    return Path(out_dir) / "runs" / f"{job.name}.json"


@dataclass
class RunFiles:
    """What ``OUT/runs`` holds for a plan."""

    done: dict = field(default_factory=dict)  # runs to reuse: Job -> run JSON
    damaged: list = field(default_factory=list)  # files to redo: (path, why)
    other: list = field(default_factory=list)  # runs made under other settings: (path, the settings that differ)


def _not_a_run(data) -> str | None:
    """Why ``data`` is not a finished percept run (a key missing or of the wrong type), or None."""
    if not isinstance(data, dict) or "error" in data or not isinstance(data.get("frames"), int):
        return "not a percept run"
    bad = [k for k in COUNTS if not isinstance(data.get(k), int)] + [g for g in groups()
                                                                    if not isinstance(data.get(g), dict)]
    return f"not a percept run (no valid {', '.join(bad)})" if bad else None


def read_run(path: Path, job: Job) -> tuple[dict | None, str | None]:
    """(run JSON, None) or (None, why the file is not a finished run of ``job``)."""
    try:
        data = json.loads(path.read_text())
    except UnicodeDecodeError:
        return None, "not text"
    except json.JSONDecodeError:
        return None, "empty" if path.stat().st_size == 0 else "not JSON (truncated?)"
    except OSError as e:
        return None, f"unreadable ({e.strerror or e})"
    if why := _not_a_run(data):
        return None, why
    if (data.get("scenario"), data.get("condition"), data.get("seed")) != (job.scenario, job.condition, job.seed):
        return None, f"a run of another job ({data.get('scenario')}-{data.get('condition')}-{data.get('seed')})"
    return data, None


def scan_runs(plan: EvalPlan, out_dir: Path) -> RunFiles:
    """Sort the run files of ``plan`` in ``out_dir/runs``; ValueError when a folder (or the runs folder itself is a
    file) is in the way."""
    runs, found, settings = Path(out_dir) / "runs", RunFiles(), run_settings(plan)
    if runs.exists() and not runs.is_dir():
        raise ValueError(f"{runs} is a file where the runs folder belongs; move it away or choose another --out")
    for job in plan.jobs:
        path = run_path(out_dir, job)
        if not path.exists():
            continue
        if path.is_dir():
            raise ValueError(f"{path} is a folder where a run file belongs; move it away or choose another --out")
        data, why = read_run(path, job)
        if data is None:
            found.damaged.append((path, why))
        elif diff := differences(settings, data.get("settings")):
            found.other.append((path, diff))
        else:
            found.done[job] = data
    return found


def refuse_other_settings(files: RunFiles, out_dir: Path) -> None:
    """ValueError naming the settings that differ when ``files`` holds runs made with other settings."""
    if files.other:
        path, diff = files.other[0]
        raise ValueError(f"{len(files.other)} run(s) in {Path(out_dir) / 'runs'} were made with other settings "
                         f"(e.g. {path.name}: {'; '.join(diff)}); give a new --out, or --redo to drive them again")
