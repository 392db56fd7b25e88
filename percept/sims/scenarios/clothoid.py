"""A highway-env lane along a clothoid (Euler spiral): the transition curve real roads put between a straight
and an arc, or between two arcs, so that curvature changes linearly with distance instead of in a step.

highway-env has straight, circular, sine and sampled poly-line lanes but no clothoid, and its arcs meet
straights with a curvature step that no real highway has (and that no steering can follow). Design
guides size the transition by travel time: AASHTO, "A Policy on Geometric Design of Highways and Streets"
(2018), 3.3.8.2: a desirable spiral length is the distance covered in 2.0 s at the design speed.

Geometry (highway-env's plane, y to the right, heading + clockwise, so curvature k > 0 turns right): the
reference line starts at p0 with heading theta0 and curvature k0 and reaches k1 after L_ref metres,
    theta(u) = theta0 + k0 u + (k1 - k0) u^2 / (2 L_ref),   p(u) = p0 + int_0^u (cos theta, sin theta) du'.
A lane whose centre lies ``offset`` to the right of the reference line has arc length
    s(u) = u - offset (theta(u) - theta0)        (ds = (1 - offset k) du),
which is the lane's own longitudinal coordinate, as highway-env expects of every lane.
"""

from __future__ import annotations

import math

import numpy as np
from highway_env.road.lane import AbstractLane, LineType

_STEP_M = 0.05
"""Integration step of the reference line: trapezoid error ~ h^2 k^2 / 12 per metre, far below a millimetre."""
_TABLE_M = 0.5
"""Spacing of the lane-centre table used to find the nearest point (refined by two Newton steps)."""


class ClothoidLane(AbstractLane):
    """A lane offset ``offset_m`` to the right of a clothoid reference line (see the module docstring)."""

    def __init__(self, start: np.ndarray, heading: float, length_ref_m: float, k0_1pm: float, k1_1pm: float,
                 offset_m: float = 0.0, width: float = AbstractLane.DEFAULT_WIDTH,
                 line_types: tuple[LineType, LineType] | list | None = None, forbidden: bool = False,
                 speed_limit: float = 20.0, priority: int = 0):
        self.start = np.asarray(start, dtype=float)
        self.theta0, self.length_ref = float(heading), float(length_ref_m)
        self.k0, self.k1, self.offset = float(k0_1pm), float(k1_1pm), float(offset_m)
        if self.length_ref <= 0:
            raise ValueError("a clothoid needs a positive length")
        if max(abs(self.k0), abs(self.k1)) * abs(self.offset) >= 0.9:
            raise ValueError("the lane offset is beyond the centre of curvature")
        self.width = float(width)
        self.line_types = list(line_types or [LineType.STRIPED, LineType.STRIPED])
        self.forbidden, self.speed_limit, self.priority = forbidden, speed_limit, priority
        # reference line by the trapezoid rule on a fine grid
        n = max(int(np.ceil(self.length_ref / _STEP_M)), 2)
        u = np.linspace(0.0, self.length_ref, n + 1)
        th = self._theta_u(u)
        c, s = np.cos(th), np.sin(th)
        du = np.diff(u)
        x = self.start[0] + np.concatenate([[0.0], np.cumsum((c[1:] + c[:-1]) / 2 * du)])
        y = self.start[1] + np.concatenate([[0.0], np.cumsum((s[1:] + s[:-1]) / 2 * du)])
        self._h, self._n = self.length_ref / n, n
        self._rx, self._ry = x.tolist(), y.tolist()
        # s(u) = u - offset (theta(u) - theta0)
        self.length = float(self.length_ref - self.offset * (th[-1] - self.theta0))
        # coarse table of lane centres for the nearest-point search, and a bounding circle for far points
        m = max(int(np.ceil(self.length / _TABLE_M)), 2)
        self._tab_s = np.linspace(0.0, self.length, m + 1)
        self._tab_c = np.array([self.position(si, 0.0) for si in self._tab_s])
        self._mid = self._tab_c.mean(axis=0)
        self._reach = float(np.max(np.linalg.norm(self._tab_c - self._mid, axis=1)))
        # the chord from start to end: unit direction and lane length per metre of chord, for far points
        (ax, ay), (bx, by) = self._tab_c[0], self._tab_c[-1]
        chord = max(math.hypot(bx - ax, by - ay), 1e-9)
        self._chord = (float(ax), float(ay), (bx - ax) / chord, (by - ay) / chord, self.length / chord)

    def _theta_u(self, u):
        # theta(u) = theta0 + k0 u + (k1 - k0) u^2 / (2 L_ref)
        return self.theta0 + self.k0 * u + (self.k1 - self.k0) * u * u / (2 * self.length_ref)

    def _u_of_s(self, s: float) -> float:
        # beyond either end the reference line continues as an arc of the end curvature: ds = (1 - offset k) du
        if s <= 0.0:
            return s / (1.0 - self.offset * self.k0)
        if s >= self.length:
            return self.length_ref + (s - self.length) / (1.0 - self.offset * self.k1)
        # s = b u + a u^2 with b = 1 - offset k0, a = -offset (k1 - k0) / (2 L_ref): the stable root
        a = -self.offset * (self.k1 - self.k0) / (2 * self.length_ref)
        b = 1.0 - self.offset * self.k0
        return 2.0 * s / (b + math.sqrt(b * b + 4.0 * a * s))

    def _centre(self, longitudinal: float) -> tuple[float, float, float]:
        """Lane centre (x, y) [m] and heading [rad] at a longitudinal coordinate (arcs beyond the ends)."""
        u = self._u_of_s(longitudinal)
        uc = min(max(u, 0.0), self.length_ref)
        g = uc / self._h
        i = min(int(g), self._n - 1)
        f = g - i
        x = self._rx[i] * (1 - f) + self._rx[i + 1] * f
        y = self._ry[i] * (1 - f) + self._ry[i + 1] * f
        th_c = self._theta_u(uc)
        e = u - uc
        if e != 0.0:
            # along an arc of curvature k for e metres: sin(k e)/k ahead, (1 - cos(k e))/k to the right
            k = self.k0 if e < 0 else self.k1
            ke = k * e
            ahead = e if abs(ke) < 1e-9 else math.sin(ke) / k
            right = 0.0 if abs(ke) < 1e-9 else (1.0 - math.cos(ke)) / k
            c, s = math.cos(th_c), math.sin(th_c)
            x, y = x + ahead * c - right * s, y + ahead * s + right * c
            th_c += ke
        c, s = math.cos(th_c), math.sin(th_c)
        d = self.offset
        return x - d * s, y + d * c, th_c

    def curvature_at(self, longitudinal: float) -> float:
        """Curvature of the lane centre [1/m] (highway-env sign: + turning right): k / (1 - offset k); the end
        values beyond the ends."""
        u = min(max(self._u_of_s(longitudinal), 0.0), self.length_ref)
        k = self.k0 + (self.k1 - self.k0) * u / self.length_ref
        return k / (1 - self.offset * k)

    def heading_at(self, longitudinal: float) -> float:
        return self._centre(float(longitudinal))[2]

    def position(self, longitudinal: float, lateral: float) -> np.ndarray:
        x, y, th = self._centre(float(longitudinal))
        return np.array([x - lateral * math.sin(th), y + lateral * math.cos(th)])

    def local_coordinates(self, position: np.ndarray) -> tuple[float, float]:
        px, py = float(position[0]), float(position[1])
        dx, dy = px - self._mid[0], py - self._mid[1]
        if dx * dx + dy * dy > (self._reach + 60.0) ** 2:
            # far from this lane: project on the chord (only distance rankings use such points)
            ax, ay, tx, ty, per_m = self._chord
            qx, qy = px - ax, py - ay
            return (qx * tx + qy * ty) * per_m, tx * qy - ty * qx
        k = int(np.argmin((self._tab_c[:, 0] - px) ** 2 + (self._tab_c[:, 1] - py) ** 2))
        s = float(self._tab_s[k])
        for _ in range(2):
            # Newton step: s += (p - c(s)) . t / (1 - r k), r = (p - c(s)) . n, as a point r to the right of the
            # centre line moves (1 - r k) metres per metre of s
            x, y, th = self._centre(s)
            c, sn = math.cos(th), math.sin(th)
            r = -(px - x) * sn + (py - y) * c
            s += ((px - x) * c + (py - y) * sn) / max(1.0 - r * self.curvature_at(s), 0.1)
        x, y, th = self._centre(s)
        return s, -(px - x) * math.sin(th) + (py - y) * math.cos(th)

    def width_at(self, longitudinal: float) -> float:
        return self.width

    @classmethod
    def from_config(cls, config: dict):
        return cls(**config)

    def to_config(self) -> dict:
        return {"class_path": f"{__name__}.ClothoidLane",
                "config": {"start": self.start.tolist(), "heading": self.theta0, "length_ref_m": self.length_ref,
                           "k0_1pm": self.k0, "k1_1pm": self.k1, "offset_m": self.offset, "width": self.width,
                           "line_types": self.line_types, "forbidden": self.forbidden,
                           "speed_limit": self.speed_limit, "priority": self.priority}}
