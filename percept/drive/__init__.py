"""Composition: the agent, the closed loop, scoring, batch evaluation and benchmarks."""

from .bench import StageCost, bench_lanes, bench_render, median_ms
from .batch import Engine, EvalPlan, Job, evaluate, parse_seeds, summarize
from .loop import SLOTS, DriveConfig, Mode, run_drive
from .privileged import PrivilegedLateral, PrivilegedLongitudinal, in_path_obstacle
from .scoring import RunScorer

__all__ = ["SLOTS", "DriveConfig", "Engine", "EvalPlan", "Job", "Mode", "PrivilegedLateral", "PrivilegedLongitudinal",
           "RunScorer", "StageCost",
           "bench_lanes", "bench_render", "evaluate", "in_path_obstacle", "median_ms", "parse_seeds", "run_drive",
           "summarize"]
