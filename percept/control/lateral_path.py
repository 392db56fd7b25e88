"""A lateral path across the lane: the minimum-jerk quintic lane keeping follows during a lane change.

Among all paths from (y0, y0', y0'') to (y1, 0, 0) in time T, the quintic minimises the integral of the squared
jerk (Flash & Hogan 1985; Werling et al., ICRA 2010, for lane changes). From rest to rest over a distance D its
peak lateral acceleration is 10 D / (sqrt(3) T^2) ~ 5.77 D / T^2 and its peak jerk 60 D / T^3: a 4 m change in
5 s asks 0.92 m/s² and 1.92 m/s³.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class LateralRef:
    """Where lane keeping should hold the car across its lane at this frame."""

    offset_m: float  # the offset from the lane centre to hold [m] (+ left, as LaneEstimate.offset_m)
    rate_mps: float  # its rate of change [m/s]
    accel_mps2: float  # its second derivative [m/s²]
    max_jerk_mps3: float | None = None  # the most lateral jerk lane keeping may add up to while following it, its
    # corrections included [m/s³] (None: unbounded, as on a swerve)


@dataclass(frozen=True)
class MinJerkPath:
    """y(t) = sum c_i t^i, i = 0..5, from (y0, v0, a0) at t = 0 to (y1, 0, 0) at t = T."""

    coeffs: tuple  # (c0 .. c5)
    duration_s: float  # T [s]

    @classmethod
    def between(cls, y0: float, v0: float, a0: float, y1: float, duration_s: float) -> "MinJerkPath":
        """The quintic from offset ``y0`` [m], rate ``v0`` [m/s] and acceleration ``a0`` [m/s²] to rest at ``y1``
        after ``duration_s`` [s]; ValueError on a duration that is not positive."""
        if not duration_s > 0:
            raise ValueError(f"duration_s must be positive, got {duration_s}")
        T = duration_s
        c0, c1, c2 = y0, v0, a0 / 2
        # the end conditions y(T) = y1, y'(T) = 0, y''(T) = 0 fix c3, c4, c5
        A = np.array([[T ** 3, T ** 4, T ** 5], [3 * T ** 2, 4 * T ** 3, 5 * T ** 4], [6 * T, 12 * T ** 2, 20 * T ** 3]])
        b = np.array([y1 - (c0 + c1 * T + c2 * T * T), -(c1 + 2 * c2 * T), -2 * c2])
        c3, c4, c5 = np.linalg.solve(A, b)
        return cls((c0, c1, c2, float(c3), float(c4), float(c5)), T)

    @property
    def extent_m(self) -> tuple[float, float]:
        """The least and the largest offset the path reaches [m]."""
        c, T = self.coeffs, self.duration_s
        # y' = c1 + 2 c2 t + 3 c3 t^2 + 4 c4 t^3 + 5 c5 t^4 = 0 inside (0, T), and the ends
        roots = np.roots([5 * c[5], 4 * c[4], 3 * c[3], 2 * c[2], c[1]]) if any(c[1:]) else []
        times = [0.0, T] + [float(r.real) for r in roots if abs(r.imag) < 1e-9 and 0 < r.real < T]
        ys = [self.at(t).offset_m for t in times]
        return min(ys), max(ys)

    @property
    def peak_jerk_mps3(self) -> float:
        """The largest size of the path's jerk [m/s³]."""
        c, T = self.coeffs, self.duration_s
        # y(3) = 6 c3 + 24 c4 t + 60 c5 t^2: a parabola, largest in size at an end or at its vertex t = -c4 / (5 c5)
        vertex = [-c[4] / (5 * c[5])] if c[5] != 0 and 0 < -c[4] / (5 * c[5]) < T else []
        return max(abs(6 * c[3] + 24 * c[4] * t + 60 * c[5] * t * t) for t in [0.0, T, *vertex])

    def at(self, t_s: float) -> LateralRef:
        """The path at ``t_s`` [s] (held at its end after T)."""
        t = min(max(t_s, 0.0), self.duration_s)
        c = self.coeffs
        y = c[0] + t * (c[1] + t * (c[2] + t * (c[3] + t * (c[4] + t * c[5]))))
        v = c[1] + t * (2 * c[2] + t * (3 * c[3] + t * (4 * c[4] + t * 5 * c[5])))
        a = 2 * c[2] + t * (6 * c[3] + t * (12 * c[4] + t * 20 * c[5]))
        return LateralRef(float(y), float(v), float(a))
