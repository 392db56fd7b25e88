"""Batch evaluation: the closed loop over scenarios x conditions x seeds (locally or on Ray), resuming, and the
reports and plots a person reads."""

from .batch import Engine, EvalPlan, Job, evaluate, parse_seeds, summarize
from .environment import environments, numeric_environment

__all__ = ["Engine", "EvalPlan", "Job", "environments", "evaluate", "numeric_environment", "parse_seeds",
           "summarize"]
