"""Batch evaluation: the closed loop over scenarios x conditions x seeds (locally or on Ray), resuming, and the
reports and plots a person reads."""

from .batch import Engine, EvalPlan, Job, evaluate, parse_seeds, summarize
from .environment import environments, numeric_environment
from .report import SUMMARY_STARTS, written_by_eval

__all__ = ["SUMMARY_STARTS", "Engine", "EvalPlan", "Job", "environments", "evaluate", "numeric_environment",
           "parse_seeds", "summarize", "written_by_eval"]
