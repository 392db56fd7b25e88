"""Controllers shared by the task modules: a small base class and the vehicle model they invert."""

from .base import Controller, sideslip_for_curvature, steering_for_curvature

__all__ = ["Controller", "sideslip_for_curvature", "steering_for_curvature"]
