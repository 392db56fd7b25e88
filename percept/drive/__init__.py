"""The closed loop: the slot table, the agent and its slots, one drive run and its scoring against ground truth.

The names load on first use (PEP 562), so that reading the slot table (the CLI builds its options from it) does not
import the simulator.
"""

from importlib import import_module

_HOME = {"Agent": "agent", "AgentStep": "agent", "DriveConfig": "config", "run_drive": "loop",
         "TruthFeed": "privileged", "in_path_obstacle": "privileged", "StepTruth": "scoring", "TASKS": "tasks",
         "Headline": "tasks", "SlotContext": "tasks", "Task": "tasks", "task_order": "tasks",
         "truth_neighbours": "neighbours_truth"}

__all__ = sorted(_HOME) + ["Source"]


def __getattr__(name: str):
    if name == "Source":
        from percept.sensors import Source

        return Source
    if name in _HOME:
        return getattr(import_module(f"{__name__}.{_HOME[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
