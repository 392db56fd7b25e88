"""Kalman filter (filterpy) over (offset, heading, curvature, width) with the car's motion as prediction.

Prediction over dt with speed v and measured yaw rate r (small angles, lane fixed in the world):
offset' = offset + v dt (heading + beta), heading' = heading + (r - v curvature) dt, curvature and width as
random walks. The measurement is the frame's fit. Confidence decays while evidence is missing.
Reference: Dickmanns & Mysliwetz, "Recursive 3-D road and relative ego-state recognition", PAMI 1992.
"""

from __future__ import annotations

import math

import numpy as np
from filterpy.kalman import KalmanFilter

from .types import LaneEstimate, LaneFit


class LaneTracker:
    """Tracks the ego lane; ``predict`` every frame, ``update`` when a fit exists."""

    def __init__(self, width_prior_m: float = 3.7):
        self.width_prior = width_prior_m
        self.reset()

    def reset(self) -> None:
        kf = KalmanFilter(dim_x=4, dim_z=4)
        kf.x = np.array([0.0, 0.0, 0.0, self.width_prior])
        kf.P = np.diag([1.0, 0.05, 1e-4, 0.25])
        kf.H = np.eye(4)
        self.kf = kf
        self.initialised = False
        self.confidence = 0.0

    def predict(self, speed_mps: float, yaw_rate_rps: float, dt: float) -> None:
        v = speed_mps if math.isfinite(speed_mps) else 0.0
        r = yaw_rate_rps if math.isfinite(yaw_rate_rps) else 0.0
        F = np.array([[1, v * dt, 0, 0], [0, 1, -v * dt, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])
        B = np.array([[0.0], [dt], [0.0], [0.0]])
        # process noise per second: lateral drift, heading, curvature change along the road, width change
        Q = np.diag([0.02 ** 2, 0.004 ** 2, (2e-4 + 2e-5 * v) ** 2, 0.01 ** 2]) * max(dt, 1e-3) * 15
        self.kf.predict(u=np.array([r]), B=B, F=F, Q=Q)
        self.confidence *= 0.85

    def update(self, fit: LaneFit) -> None:
        e = fit.estimate
        z = np.array([e.offset_m, e.heading_rad, e.curvature_1pm, e.width_m])
        # the fit's covariance, inflated for correlated pixel errors, with a floor per parameter
        R = 4.0 * fit.cov + np.diag([0.01 ** 2, 0.001 ** 2, 2e-5 ** 2, 0.02 ** 2])
        if not self.initialised:
            self.kf.x = z.copy()
            self.kf.P = R * 4
            self.initialised = True
        else:
            # reject fits far from the prediction (Mahalanobis gate, chi2 4 dof, 99.9 %)
            y = z - self.kf.x
            S = self.kf.P + R
            if float(y @ np.linalg.solve(S, y)) > 18.5 and self.confidence > 0.3:
                return
            self.kf.update(z, R=R)
        self.confidence = min(1.0, 0.5 * self.confidence + 0.5 * e.confidence + 0.2)

    @property
    def estimate(self) -> LaneEstimate:
        x = self.kf.x
        return LaneEstimate(float(x[0]), float(x[1]), float(x[2]), float(x[3]), float(self.confidence),
                            valid=self.initialised)
