"""Pinhole camera model.

Camera frame is OpenCV's: x right, y down, z forward (metres). Image points are
``(u, v) = (col, row)`` in pixels; arrays of images are indexed ``[row, col]``.
Reference: Hartley & Zisserman, *Multiple View Geometry*, 2nd ed., ch. 6.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class PinholeCamera:
    """Intrinsics of an undistorted pinhole camera."""

    fx: float  # focal length along the columns [px]
    fy: float  # focal length along the rows [px]
    cx: float  # principal point's column [px]
    cy: float  # principal point's row [px]
    width: int  # image width [px]
    height: int  # image height [px]

    def __post_init__(self) -> None:
        if not (self.fx > 0 and self.fy > 0):
            raise ValueError(f"focal lengths must be positive, got fx={self.fx}, fy={self.fy}")
        if self.width < 16 or self.height < 16:
            raise ValueError(f"image size {self.width}x{self.height} is too small (min 16x16)")

    @classmethod
    def from_hfov(cls, width: int, height: int, hfov_rad: float) -> "PinholeCamera":
        """Square pixels, principal point at the image centre, horizontal field of view ``hfov_rad``."""
        if not 0.05 < hfov_rad < math.pi - 0.05:
            raise ValueError(f"horizontal field of view {hfov_rad:.3f} rad is outside (0.05, pi-0.05)")
        # fx = (W/2) / tan(hfov/2)
        f = (width / 2.0) / math.tan(hfov_rad / 2.0)
        return cls(f, f, (width - 1) / 2.0, (height - 1) / 2.0, int(width), int(height))

    @property
    def K(self) -> np.ndarray:
        """3x3 intrinsic matrix."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    @property
    def K_inv(self) -> np.ndarray:
        return np.linalg.inv(self.K)

    @property
    def hfov_rad(self) -> float:
        return 2.0 * math.atan(self.width / (2.0 * self.fx))

    def project(self, points_cam: np.ndarray) -> np.ndarray:
        """Camera-frame points (N, 3) [m] -> pixels (N, 2) as (u, v). Points must have z > 0."""
        p = np.asarray(points_cam, dtype=np.float64)
        # u = fx x / z + cx ; v = fy y / z + cy
        z = p[..., 2]
        u = self.fx * p[..., 0] / z + self.cx
        v = self.fy * p[..., 1] / z + self.cy
        return np.stack([u, v], axis=-1)

    def rays(self) -> np.ndarray:
        """Normalised rays (H, W, 3) through every pixel centre, camera frame, with z = 1."""
        u = np.arange(self.width, dtype=np.float64)
        v = np.arange(self.height, dtype=np.float64)
        uu, vv = np.meshgrid(u, v)
        return np.stack([(uu - self.cx) / self.fx, (vv - self.cy) / self.fy, np.ones_like(uu)], axis=-1)

    def to_dict(self) -> dict:
        return {"fx": self.fx, "fy": self.fy, "cx": self.cx, "cy": self.cy, "width": self.width, "height": self.height}
