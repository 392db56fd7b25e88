"""The lead's range filter: a Kalman filter (filterpy) over range, range rate and range acceleration.

Constant acceleration with white jerk noise, so that a lead braking hard is followed without lag; each measurement
(a range or a range rate) is scalar and gated at a number of sigma; a floor on the range rate (nothing in the ego's
path comes towards it faster than it drives) is kept by projecting the estimate after every prediction and update.
References: Bar-Shalom, Li & Kirubarajan, *Estimation with Applications to Tracking and Navigation*, 2001, sec. 6.2.3
(white jerk); Simon, "Kalman filtering with state constraints", IET Control Theory Appl. 4(8), 2010 (estimate
projection).
"""

from __future__ import annotations

import numpy as np
from filterpy.kalman import KalmanFilter

RANGE, RATE = 0, 1
"""The measured states, as indices into the filter's state (range [m], range rate [m/s], range acceleration
[m/s²])."""
_H = (np.array([[1.0, 0.0, 0.0]]), np.array([[0.0, 1.0, 0.0]]))
"""Their measurement rows H, by index i: H x = x[i] and H P H^T = P[i, i] (exactly: the other terms are 0 times a
finite value)."""


def _inverse_1x1(S: np.ndarray) -> np.ndarray:
    """The filter's ``inv`` for its (1, 1) innovation covariance: [[1 / s]], what ``np.linalg.inv``'s LU solve gives
    bit for bit, without its generic machinery on every update."""
    return 1.0 / S


class RangeFilter:
    """One lead's range track, started from a stereo range ``z_m`` with noise ``sigma_m`` [m]; dt_s: the frame
    period [s]; jerk_sigma_mps3: white jerk noise [m/s³]; rate_floor_mps: the range rate's floor until the next
    ``predict`` [m/s] (-inf: none)."""

    def __init__(self, z_m: float, sigma_m: float, dt_s: float, jerk_sigma_mps3: float,
                 rate_floor_mps: float = -np.inf):
        kf = KalmanFilter(dim_x=3, dim_z=1)
        kf.inv = _inverse_1x1
        dt, q = dt_s, jerk_sigma_mps3 ** 2
        kf.F = np.array([[1.0, dt, dt * dt / 2], [0.0, 1.0, dt], [0.0, 0.0, 1.0]])
        kf.H = _H[RANGE]
        # white jerk: Q = q [[dt^5/20, dt^4/8, dt^3/6], [dt^4/8, dt^3/3, dt^2/2], [dt^3/6, dt^2/2, dt]]
        kf.Q = q * np.array([[dt ** 5 / 20, dt ** 4 / 8, dt ** 3 / 6], [dt ** 4 / 8, dt ** 3 / 3, dt ** 2 / 2],
                             [dt ** 3 / 6, dt ** 2 / 2, dt]])
        kf.x = np.array([[z_m], [0.0], [0.0]])
        kf.P = np.diag([sigma_m ** 2, 10.0 ** 2, 5.0 ** 2])
        self.kf = kf
        self.rate_floor_mps = rate_floor_mps

    @property
    def range_m(self) -> float:
        return float(self.kf.x[RANGE, 0])

    @property
    def rate_mps(self) -> float:
        return float(self.kf.x[RATE, 0])

    def predict(self, rate_floor_mps: float) -> None:
        """One frame ahead, then this frame's floor on the range rate (-inf: none)."""
        self.rate_floor_mps = rate_floor_mps
        self.kf.predict()
        self._constrain()

    def gated_update(self, value: float, sigma: float, i: int, gate_sigma: float) -> bool:
        """One measurement ``value`` of state ``i`` (RANGE or RATE) with noise ``sigma``, unless its innovation is
        beyond ``gate_sigma`` sigma; True if used."""
        # innovation variance s = H P H^T + R = P[i, i] + sigma^2, innovation value - H x = value - x[i]
        s = float(self.kf.P[i, i] + sigma ** 2)
        innovation = value - float(self.kf.x[i, 0])
        if innovation * innovation > gate_sigma ** 2 * s:
            return False
        self._apply(value, np.array([[sigma ** 2]]), i)
        return True

    def manoeuvre(self, z_m: float, sigma_m: float, rate_mps: float, accel_mps2: float) -> None:
        """The lead manoeuvring (braking hard): the range, rate and acceleration variances grow by sigma_m²,
        rate_mps² and accel_mps2², then the range ``z_m`` is taken whatever its innovation."""
        self.kf.P += np.diag([sigma_m ** 2, rate_mps ** 2, accel_mps2 ** 2])
        self._apply(z_m, np.array([[sigma_m ** 2]]), RANGE)

    def _apply(self, value: float, R: np.ndarray, i: int) -> None:
        """The filter's update with one measurement of state ``i``, then the rate floor. The measurement goes in as a
        float: y = z - H x is the same (1, 1) array, and the filter's copy of z (``deepcopy``) is far cheaper."""
        self.kf.update(value, R=R, H=_H[i])
        self._constrain()

    def _constrain(self) -> None:
        """Hold the range rate at or above the floor: estimate projection onto D x >= d, D = [0 1 0]:
        x <- x - P D^T (D P D^T)^-1 (D x - d), which also moves the range and acceleration by their correlation
        with the rate."""
        excess = float(self.kf.x[1, 0]) - self.rate_floor_mps
        if excess < 0:
            self.kf.x = self.kf.x - self.kf.P[:, 1:2] / self.kf.P[1, 1] * excess
