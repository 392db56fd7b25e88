"""The motion model every person track shares over one frame: the ego's own travel and turn, and the people's
white-noise acceleration (Bar-Shalom, Li & Kirubarajan 2001, ch. 6), built once a frame for all tracks."""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from filterpy.common import Q_discrete_white_noise


@dataclass(frozen=True)
class EgoStep:
    """The motion model of every track over one frame of the ego's own motion (read-only arrays): rt (2, 2), R(th)^T
    for the turn th; f (4, 4) and b (4, 2) with x_k+1 = F x_k + B t for the ego's travel t (2,) [m]; q (4, 4) the
    white-noise acceleration's covariance."""

    rt: np.ndarray
    f: np.ndarray
    b: np.ndarray
    q: np.ndarray
    travel: np.ndarray

    @classmethod
    def of(cls, dt: float, ego_speed_mps: float, yaw_rate_rps: float, accel_mps2: float) -> "EgoStep":
        """The step over dt [s] at ``ego_speed_mps`` turning at ``yaw_rate_rps``, people's white-noise acceleration
        ``accel_mps2`` [m/s²]."""
        th = yaw_rate_rps * dt
        c, s = np.cos(th), np.sin(th)
        rt = np.array([[c, s], [-s, c]])  # R(th)^T: the old vehicle frame's vectors in the new one
        # p_k+1 = R^T (p_k + v_k dt - t), v_k+1 = R^T v_k, with the ego's travel t = v_ego dt (cos th/2, sin th/2)
        # (the chord of its arc): the ego's own motion moves and turns everything the other way
        f = np.zeros((4, 4))
        f[:2, :2], f[:2, 2:], f[2:, 2:] = rt, rt * dt, rt
        b = np.zeros((4, 2))
        b[:2] = -rt
        travel = ego_speed_mps * dt * np.array([np.cos(th / 2), np.sin(th / 2)])
        for a in (rt, f, b, travel):
            a.flags.writeable = False
        return cls(rt, f, b, _white_noise(dt, accel_mps2 ** 2), travel)


@lru_cache(maxsize=8)
def _white_noise(dt: float, var: float) -> np.ndarray:
    """filterpy's white-noise acceleration covariance (4, 4) of (x, y, vx, vy) over dt [s] (read-only)."""
    q = Q_discrete_white_noise(2, dt, var, block_size=2, order_by_dim=False)
    q.flags.writeable = False
    return q
