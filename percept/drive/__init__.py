"""The closed loop: the slot table, the agent and its slots, one drive run and its scoring against ground truth."""

from percept.sensors import Source

from .agent import Agent, AgentStep
from .config import DriveConfig
from .loop import run_drive
from .privileged import TruthFeed, in_path_obstacle
from .scoring import StepTruth
from .tasks import TASKS, Headline, SlotContext, Task, task_order

__all__ = ["TASKS", "Agent", "AgentStep", "DriveConfig", "Headline", "SlotContext", "Source", "StepTruth", "Task",
           "TruthFeed", "in_path_obstacle", "run_drive", "task_order"]
