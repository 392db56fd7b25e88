"""Records passed out of the lanes module."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class LaneEstimate:
    """The ego lane in the vehicle frame (x forward, y left), as the lateral controller needs it.

    offset_m: vehicle centre's lateral offset from the lane centre (+ left); heading_rad: vehicle heading relative
    to the lane (+ CCW); curvature_1pm: lane curvature (+ turning left); width_m; confidence: 0..1 (0 = no
    evidence, the values are a prediction); valid: False before the first fit; curvature_rate_1pm2: change of
    the curvature per metre ahead (a clothoid). The lane centre in the vehicle frame is
    y_c(x) = -offset - tan(heading) x + curvature x^2 / 2 + curvature_rate x^3 / 6.
    """

    offset_m: float
    heading_rad: float
    curvature_1pm: float
    width_m: float
    confidence: float
    valid: bool = True
    curvature_rate_1pm2: float = 0.0

    def centre_y(self, x_m: np.ndarray) -> np.ndarray:
        """Lateral position of the lane centre at distances x_m ahead [m]."""
        x = np.asarray(x_m, dtype=float)
        # y_c = -offset - tan(heading) x + curvature x^2 / 2 + curvature_rate x^3 / 6
        return (-self.offset_m - np.tan(self.heading_rad) * x + 0.5 * self.curvature_1pm * x * x
                + self.curvature_rate_1pm2 * x ** 3 / 6)

    def boundary_y(self, x_m: np.ndarray, side: int) -> np.ndarray:
        """side +1: left boundary, -1: right boundary."""
        return self.centre_y(x_m) + side * self.width_m / 2

    def boundary_points_m(self, x_near_m: float, x_far_m: float, n: int = 40) -> dict[str, np.ndarray]:
        """Both boundaries on the ground: {"left"|"right": (n, 3) vehicle-frame (x, y, 0) [m]}, x_near..x_far."""
        x = np.linspace(x_near_m, x_far_m, n)
        return {name: np.column_stack([x, self.boundary_y(x, side), np.zeros_like(x)])
                for name, side in (("left", 1), ("right", -1))}


@dataclass(frozen=True)
class MarkingEvidence:
    """Marking pixels mapped to the ground. points_m: (N, 2) vehicle-frame (x, y) [m]; strength: (N,) top-hat
    response; uv_px: (N, 2) where they are in the image (u, v); weight: (N,) how much independent image evidence
    each point carries, 0..1 (far grid rows re-sample the same image rows, and a far pixel spans more ground);
    None = all 1."""

    points_m: np.ndarray
    strength: np.ndarray
    uv_px: np.ndarray
    weight: np.ndarray | None = None


@dataclass(frozen=True)
class LaneFit:
    """One frame's robust fit. estimate: the fitted lane (confidence from support); side: (N,) +1 left,
    -1 right, 0 outlier, per evidence point; residual_m: RMS residual of the inliers [m]; cov: (5, 5)
    covariance of (offset, heading, curvature, curvature_rate, width) from the least-squares normal equations."""

    estimate: LaneEstimate
    side: np.ndarray
    residual_m: float
    inliers_left: int
    inliers_right: int
    cov: np.ndarray
