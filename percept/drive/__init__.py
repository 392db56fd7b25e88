"""Composition: the slot table, the agent, the closed loop, scoring, batch evaluation and benchmarks."""

from .agent import Agent, AgentStep
from .batch import Engine, EvalPlan, Job, evaluate, parse_seeds, summarize
from .bench import StageCost, bench_render, bench_task, median_ms, slot_ms
from .config import DriveConfig
from .environment import environments, numeric_environment
from .loop import run_drive
from .privileged import TruthFeed, in_path_obstacle
from .scoring import StepTruth
from percept.sensors import Source

from .tasks import TASKS, Headline, SlotContext, Task, task_order

__all__ = ["TASKS", "Agent", "AgentStep", "DriveConfig", "Engine", "EvalPlan", "Headline", "Job", "SlotContext",
           "Source", "StageCost", "StepTruth", "Task", "TruthFeed", "bench_render", "bench_task", "environments",
           "evaluate", "in_path_obstacle", "median_ms", "numeric_environment", "parse_seeds", "run_drive", "slot_ms",
           "summarize", "task_order"]
