"""Kalman filter (filterpy) over (offset, heading, curvature, curvature rate, width), the car's motion as prediction.

Prediction over dt with speed v, measured yaw rate r and the distance travelled d = v dt (small angles, lane
fixed in the world; the curvature under the car changes along a clothoid at the curvature rate c1):
    offset'    = offset + d heading
    heading'   = heading + r dt - d (curvature + c1 d / 2)
    curvature' = curvature + c1 d
with the curvature rate and the width as random walks. The measurement is the frame's fit with its covariance.
Confidence decays while evidence is missing. The lane tracked is the one the car's centre is in: once the centre
crosses a boundary the track moves to the lane beyond (``shift``), as highway-env's own lane index does, and counts
the move in ``index``. Whether each boundary is a broken line (a lane beyond) is a vote over the frames' fits.
Reference: Dickmanns & Mysliwetz, "Recursive 3-D road and relative ego-state recognition", PAMI 1992 (the
clothoid road model with curvature rate in the state).
"""

from __future__ import annotations

import numpy as np
from filterpy.kalman import KalmanFilter

from percept.sensors import plausible_speed, plausible_yaw_rate

from .types import LaneEstimate, LaneFit


KIND_GAIN = 0.2
"""How much one frame's broken-or-solid verdict moves a boundary's vote (an exponential average over about 5 frames)."""
KIND_VOTE = 0.5
"""A boundary is broken (solid) once its vote passes +this (-this); between the two it is not known."""
SHIFT_MARGIN_M = 0.1
"""The car's centre must be this far past a boundary before the track moves to the lane beyond [m]: a centre on the
line, its offset jittering by centimetres, does not move the track back and forth."""


class LaneTracker:
    """Tracks the ego lane; ``predict`` every frame, ``update`` when a fit exists."""

    def __init__(self, width_prior_m: float = 3.7, curvature_rate_sigma_1pm2: float = 1e-4):
        self.width_prior = width_prior_m
        self.rate_sigma = curvature_rate_sigma_1pm2
        self.reset()

    def reset(self, index: int = 0) -> None:
        """Forget the lane; ``index``: the lane count to go on from (a fresh search keeps it)."""
        self.index = index  # lanes moved to the left since the first one tracked
        self.votes = np.zeros(2)  # (left, right) boundary: +1 broken ... -1 solid
        kf = KalmanFilter(dim_x=5, dim_z=5)
        kf.x = np.array([0.0, 0.0, 0.0, 0.0, self.width_prior])
        kf.P = np.diag([1.0, 0.05, 1e-4, 1e-8, 0.25])
        kf.H = np.eye(5)
        self.kf = kf
        self.initialised = False
        self.confidence = 0.0

    def predict(self, speed_mps: float, yaw_rate_rps: float, dt: float, drift: bool = True) -> None:
        """Move the lane by the car's motion over ``dt``; ``drift`` False leaves out the per-second process noise
        and the confidence's decay (a car that crawls does not drift, and a lane seen a moment ago a metre back is
        still there)."""
        # a bad sample (percept.sensors' rule) predicts no motion
        v = speed_mps if plausible_speed(speed_mps) else 0.0
        r = yaw_rate_rps if plausible_yaw_rate(yaw_rate_rps) else 0.0
        d = v * dt
        F = np.array([[1, d, 0, 0, 0], [0, 1, -d, -d * d / 2, 0], [0, 0, 1, d, 0], [0, 0, 0, 1, 0],
                      [0, 0, 0, 0, 1.0]])
        B = np.array([[0.0], [dt], [0.0], [0.0], [0.0]])
        # process noise per metre travelled (a road's shape changes along it) and per second (the car drifts):
        # lateral drift, heading, curvature, curvature rate (spirals begin and end), width
        per_m = np.diag([0.0, 0.0, 2e-5 ** 2, 2e-5 ** 2, 0.0]) * max(d, 1e-3)
        per_s = np.diag([0.02 ** 2, 0.004 ** 2, 1e-4 ** 2, 0.0, 0.01 ** 2]) * max(dt, 1e-3) * 15
        self.kf.predict(u=np.array([r]), B=B, F=F, Q=per_m + per_s if drift else per_m)
        if drift:
            self.confidence *= 0.85

    def update(self, fit: LaneFit) -> None:
        """Take one frame's fit (the first starts the track); a fit outside the gate of a confident track is ignored."""
        e = fit.estimate
        z = np.array([e.offset_m, e.heading_rad, e.curvature_1pm, e.curvature_rate_1pm2, e.width_m])
        # the fit's covariance, inflated for correlated pixel errors, with a floor per parameter
        R = 4.0 * fit.cov + np.diag([0.01 ** 2, 0.001 ** 2, 2e-5 ** 2, 1e-6 ** 2, 0.02 ** 2])
        if not self.initialised:
            self.kf.x = z.copy()
            self.kf.P = R * 4
            # one frame cannot tell the curvature rate (it bends the far end, where a few stray points decide it):
            # the track starts from the road-design prior, rate 0 +- sigma, and learns it over the next frames
            self.kf.x[3] = 0.0
            self.kf.P[3, :] = self.kf.P[:, 3] = 0.0
            self.kf.P[3, 3] = self.rate_sigma ** 2
            self.initialised = True
        else:
            # reject fits far from the prediction (Mahalanobis gate, chi2 5 dof, 99.9 %)
            y = z - self.kf.x
            S = self.kf.P + R
            if float(y @ np.linalg.solve(S, y)) > 20.5 and self.confidence > 0.3:
                return
            self.kf.update(z, R=R)
        self.confidence = min(1.0, 0.5 * self.confidence + 0.5 * e.confidence + 0.2)
        for i, broken in enumerate(fit.broken):
            if broken is not None:
                self.votes[i] += KIND_GAIN * ((1.0 if broken else -1.0) - self.votes[i])
        self._follow_the_centre()

    def _follow_the_centre(self) -> None:
        """Once the car's centre is past a boundary (|offset| > w / 2 + SHIFT_MARGIN_M), track the lane beyond
        (``shift``)."""
        offset, width = float(self.kf.x[0]), float(self.kf.x[4])
        if self.initialised and abs(offset) > width / 2 + SHIFT_MARGIN_M:
            self.shift(1 if offset > 0 else -1)

    def shift(self, side: int) -> None:
        """Track the lane beside, on ``side`` (+1 left, -1 right): offset' = offset - side w (the covariance moved
        with it), the boundary crossed now on the other side, the one beyond not yet known."""
        J = np.eye(5)
        J[0, 4] = -side
        self.kf.x = J @ self.kf.x
        self.kf.P = J @ self.kf.P @ J.T
        crossed = self.votes[0 if side > 0 else 1]
        self.votes = np.array([0.0, crossed]) if side > 0 else np.array([crossed, 0.0])
        self.index += side

    @property
    def estimate(self) -> LaneEstimate:
        """The tracked lane (invalid until the first fit) with the tracker's confidence."""
        x = self.kf.x
        beside = tuple(True if v > KIND_VOTE else False if v < -KIND_VOTE else None for v in self.votes)
        return LaneEstimate(float(x[0]), float(x[1]), float(x[2]), float(x[4]), float(self.confidence),
                            valid=self.initialised, curvature_rate_1pm2=float(x[3]), index=self.index, beside=beside)
