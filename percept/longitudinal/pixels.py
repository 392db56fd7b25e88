"""Whole image rows and columns of road points, in scalar arithmetic where the rig's array arithmetic cannot matter.

Some stages only take a whole pixel of a projected road point: the contact search the rows between which it looks
(floor and ceil of the rows at two ranges), the far band the columns it matches (floor and ceil of the corridor's
outermost columns). The rig's projection (``project_vehicle_points``: (N, 3) arrays, a matrix product, a stack) costs
~35 µs a call; the same pinhole model on a few floats costs a few µs and differs from it by rounding only, far below
``TOL_PX``. Where a value lies within ``TOL_PX`` of a whole number, the rig's own projection decides, so the whole
pixels are the rig's, always.
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np

from percept.sensors import Side, StereoRig

TOL_PX = 1e-6
"""How near a whole number the short form's value may lie before the rig's projection is asked [px] (the two
differ by ~1e-12 px for points more than MIN_DEPTH_M in front of the camera)."""
MIN_DEPTH_M = 0.1
"""Nearer the camera's plane than this (or behind it), the rig's projection is always asked [m]."""


class RoadPixels:
    """The left camera's pixels of road points (x, y, 0) in the vehicle frame: camera frame p_c = R p + t (the
    rig's transform), then u = fx x_c / z_c + cx, v = fy y_c / z_c + cy."""

    def __init__(self, rig: StereoRig):
        T, cam = rig.cam_from_vehicle(Side.LEFT), rig.camera
        self.R, self.t = T.R.tolist(), T.t.tolist()
        self.fx, self.fy, self.cx, self.cy = float(cam.fx), float(cam.fy), float(cam.cx), float(cam.cy)

    def row(self, x: float) -> float:
        """Image row of the road point (x, 0, 0); nan where it is not in front of the camera."""
        R, t = self.R, self.t
        # y_c = R10 x + t1, z_c = R20 x + t2
        yc, zc = R[1][0] * x + t[1], R[2][0] * x + t[2]
        return self.fy * yc / zc + self.cy if zc > MIN_DEPTH_M else math.nan

    def columns(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Image columns of the road points (x, y, 0) (arrays of one shape); nan where not in front of the camera."""
        return self.columns_along(x)(y)

    def columns_along(self, x: np.ndarray) -> Callable[[np.ndarray], np.ndarray]:
        """``columns(x, y)`` for these x and any y (of a shape that broadcasts with x), the x terms done once:
        u = (fx x_c) / z_c + cx with fx x_c = a + b y and z_c = c + e y."""
        R, t, fx, cx = self.R, self.t, self.fx, self.cx
        x = np.asarray(x, dtype=float)
        # x_c = R00 x + R01 y + t0, z_c = R20 x + R21 y + t2
        a, b = fx * (R[0][0] * x + t[0]), fx * R[0][1]
        c, e = R[2][0] * x + t[2], R[2][1]

        def columns(y: np.ndarray) -> np.ndarray:
            zc = c + e * y if e else c
            if np.min(zc) <= MIN_DEPTH_M:
                return np.full(np.broadcast(x, y).shape, np.nan)
            return (a + b * y) / zc + cx
        return columns


def clear(value: float) -> bool:
    """Whether a value of the short form lies more than TOL_PX from a whole number (then its floor and ceil are the
    rig's value's)."""
    return math.isfinite(value) and abs(value - round(value)) > TOL_PX


def whole(value: float, rounding: Callable[[float], float], exact: Callable[[], float]) -> int:
    """``int(rounding(v))`` (math.floor or math.ceil) of the rig's value v, given ``value`` from the short form:
    rounded as it is when it is ``clear``, else v = exact() is."""
    return int(rounding(value if clear(value) else exact()))
