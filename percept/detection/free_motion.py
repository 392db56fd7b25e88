"""A track's free motion: a constant-velocity Kalman filter (filterpy) on a person track's detections with no prior
that people barely move, which tells whether what is tracked moves like a person on foot at all.

A vehicle's tail light and wheel can read as a person's legs; the person filter's tight prior on the speed then holds
its motion near a standstill for seconds, while its detections show a vehicle's speed over the ground. The free
filter starts with a vehicle's speed uncertainty and follows the detections. One detection on another part of the
same vehicle (a taller window that puts the feet 10-16 m nearer) would drag it back to a standstill in one frame, so
its update is robust: a detection whose innovation lies beyond the gate has its measurement noise inflated by
d^2 / gate, so that (where the measurement noise dominates the innovation's) it lies on the gate, and the farther
beyond it lies the less it moves the free motion. A lasting change is followed as the filter's own uncertainty
grows. It does not help a young filter, whose own uncertainty dominates the innovation's.

References: Bar-Shalom, Li & Kirubarajan, "Estimation with Applications to Tracking and Navigation" (2001), the
white-noise-acceleration model (ch. 6) and gating (ch. 7); Chang, "Robust Kalman filtering based on Mahalanobis
distance as outlier judging criterion", Journal of Geodesy 88 (2014), the inflated measurement noise.
"""

from __future__ import annotations

import numpy as np
from filterpy.kalman import KalmanFilter


class FreeMotion:
    """The free motion of one track over the ground in the vehicle frame: state (x, y, vx, vy) [m, m/s].

    sigma_v0_mps: the first speed uncertainty (a vehicle's speed); gate_chi2: squared Mahalanobis distance beyond which
    a detection's noise is inflated by d^2 / gate (2 degrees of freedom); vehicle_min_mps, too_fast_sigmas: the
    hysteresis of ``too_fast`` (see ``update``)."""

    def __init__(self, xy: np.ndarray, r: np.ndarray, sigma_v0_mps: float, gate_chi2: float,
                 vehicle_min_mps: float, too_fast_sigmas: float):
        self.kf = constant_velocity_filter(xy, r, sigma_v0_mps)
        self.gate_chi2, self.limit_mps, self.k = gate_chi2, vehicle_min_mps, too_fast_sigmas
        self.too_fast = False
        self.speed = self._speed()

    def predict(self, f: np.ndarray, q: np.ndarray, b: np.ndarray, u: np.ndarray) -> None:
        """x' = F x + B u, P' = F P F^T + Q (the track's motion model and the ego's motion as the input)."""
        self.kf.predict(u=u, B=b, F=f, Q=q)
        self.speed = self._speed()

    def update(self, xy: np.ndarray, r: np.ndarray) -> None:
        """One detection's feet (x, y) [m] with their 2x2 covariance ``r`` [m²]."""
        kf = self.kf
        d = xy - kf.H @ kf.x
        # d^2 = (z - H x)^T S^-1 (z - H x), S = H P H^T + R
        d2 = float(d @ np.linalg.solve(kf.H @ kf.P @ kf.H.T + r, d))
        # beyond the gate, R' = R d^2 / gate (Chang 2014): d'^2 = d^T (H P H^T + R')^-1 d is then the gate where R
        # dominates S, and the update moves the state less than the unscaled one would
        kf.update(xy, R=r * (d2 / self.gate_chi2) if d2 > self.gate_chi2 else r)
        self.speed = speed, sigma = self._speed()
        # hysteresis: too fast once s - k sigma > limit, a person again once s + k sigma < limit
        self.too_fast = speed + self.k * sigma >= self.limit_mps if self.too_fast else \
            speed - self.k * sigma > self.limit_mps

    def _speed(self) -> tuple[float, float]:
        """The speed over the ground and its standard deviation along the motion [m/s]."""
        v, p = self.kf.x[2:], self.kf.P[2:, 2:]
        speed = float(np.hypot(*v))
        # sigma_|v| = sqrt(n^T P_v n), n = v / |v| (the trace's mean at a standstill, where there is no direction)
        var = float(v @ p @ v) / speed ** 2 if speed > 1e-9 else float(np.trace(p)) / 2
        return speed, float(np.sqrt(max(var, 0.0)))


def constant_velocity_filter(xy: np.ndarray, r: np.ndarray, sigma_v0_mps: float) -> KalmanFilter:
    """A filterpy filter over (x, y, vx, vy) measuring (x, y), started at ``xy`` (covariance ``r``) at rest with a
    speed uncertainty of ``sigma_v0_mps`` on each axis."""
    kf = KalmanFilter(dim_x=4, dim_z=2)
    kf.x = np.array([xy[0], xy[1], 0.0, 0.0])
    kf.H = np.array([[1.0, 0, 0, 0], [0, 1.0, 0, 0]])
    kf.P = np.diag([0.0, 0.0, sigma_v0_mps ** 2, sigma_v0_mps ** 2])
    kf.P[:2, :2] = r
    return kf
