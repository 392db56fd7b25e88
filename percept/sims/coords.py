"""The one place that converts between highway-env's plane and percept's world frame.

highway-env: x along travel, y to the *right* (screen-down), heading measured from +x towards +y.
percept world: right-handed, x forward, y left, z up; yaw counter-clockwise from +x seen from above.
So ``x_w = x_hw``, ``y_w = -y_hw``, ``yaw_w = -heading_hw``; a lateral lane coordinate of highway-env
(positive to the right) is negated to give percept's (positive to the left).
"""

from __future__ import annotations

import numpy as np

from percept.sensors import Pose2D, wrap_angle


def hw_to_world_xy(xy_hw: np.ndarray) -> np.ndarray:
    """highway-env positions (..., 2) -> world positions (..., 2)."""
    p = np.array(xy_hw, dtype=np.float64)
    p[..., 1] *= -1.0
    return p


def world_to_hw_xy(xy_w: np.ndarray) -> np.ndarray:
    """World positions (..., 2) -> highway-env positions (..., 2). (The map is its own inverse.)"""
    return hw_to_world_xy(xy_w)


def hw_to_world_yaw(heading_hw: float) -> float:
    """highway-env heading [rad] -> world yaw [rad]."""
    return float(wrap_angle(-heading_hw))


def hw_pose(obj) -> Pose2D:
    """Pose of a highway-env RoadObject in the world frame."""
    x, y = hw_to_world_xy(obj.position)
    return Pose2D(float(x), float(y), hw_to_world_yaw(obj.heading))
