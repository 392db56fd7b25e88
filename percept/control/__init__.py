"""Controllers shared by the task modules: a small base class and the vehicle model they invert."""

from .base import Controller, sideslip_for_curvature, steering_for_curvature
from .lane_keeping import LaneKeeping

__all__ = ["Controller", "LaneKeeping", "sideslip_for_curvature", "steering_for_curvature"]
