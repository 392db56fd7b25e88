"""Rigid transforms and planar poses.

World frame: right-handed, x east/forward along the road at the start, y left, z up.
Vehicle frame (ISO 8855): origin on the ground below the vehicle centre, x forward, y left, z up.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


def rotate_to_vehicle(dx, dy, c, s):
    """The vehicle-frame (x, y) of a ground offset (dx, dy) = p - t from the vehicle at t, world frame, with
    c, s = cos, sin of its yaw: [x_v, y_v] = R(-yaw) (dx, dy). Scalars or arrays alike (and compiled kernels:
    ``sims/render/paint.py`` registers it with numba)."""
    return c * dx + s * dy, -s * dx + c * dy


def rot_z(yaw_rad: float) -> np.ndarray:
    """3x3 rotation about +z by ``yaw_rad`` (counter-clockwise seen from above)."""
    c, s = math.cos(yaw_rad), math.sin(yaw_rad)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def wrap_angle(angle_rad: float | np.ndarray) -> float | np.ndarray:
    """Wrap to [-pi, pi). A float stays a float: Python's float % is numpy's (fmod, then the divisor's sign), so it
    gives the same bits without an array's overhead."""
    if isinstance(angle_rad, float):
        return (angle_rad + math.pi) % (2 * math.pi) - math.pi
    return (np.asarray(angle_rad) + math.pi) % (2 * math.pi) - math.pi


@dataclass(frozen=True)
class Transform:
    """Rigid transform ``p_dst = R @ p_src + t``. R: (3, 3) rotation, t: (3,) [m]."""

    R: np.ndarray
    t: np.ndarray

    def apply(self, points: np.ndarray) -> np.ndarray:
        """Transform points (N, 3) or (3,)."""
        return np.asarray(points) @ self.R.T + self.t

    def inverse(self) -> "Transform":
        return Transform(self.R.T, -self.R.T @ self.t)

    def compose(self, other: "Transform") -> "Transform":
        """``self ∘ other``: first ``other``, then ``self``."""
        return Transform(self.R @ other.R, self.R @ other.t + self.t)

    def matrix(self) -> np.ndarray:
        m = np.eye(4)
        m[:3, :3] = self.R
        m[:3, 3] = self.t
        return m


@dataclass(frozen=True)
class Pose2D:
    """Planar pose of the vehicle frame in the world frame: x_m, y_m [m], yaw_rad [rad, CCW from +x]."""

    x_m: float
    y_m: float
    yaw_rad: float

    def world_from_vehicle(self) -> Transform:
        """Transform taking vehicle-frame points to world-frame points."""
        return Transform(rot_z(self.yaw_rad), np.array([self.x_m, self.y_m, 0.0]))

    def vehicle_from_world(self) -> Transform:
        return self.world_from_vehicle().inverse()

    def to_vehicle_xy(self, xy_world: np.ndarray) -> np.ndarray:
        """World points (N, 2) -> vehicle frame (N, 2), both on the ground plane."""
        c, s = math.cos(self.yaw_rad), math.sin(self.yaw_rad)
        d = np.asarray(xy_world, dtype=np.float64) - np.array([self.x_m, self.y_m])
        return np.stack(rotate_to_vehicle(d[..., 0], d[..., 1], c, s), axis=-1)
