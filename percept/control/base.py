"""The controller base class and the kinematic-bicycle inversion used by lateral controllers."""

from __future__ import annotations

import math
from abc import ABC, abstractmethod

WHEELBASE_M = 5.0
"""highway-env's Vehicle integrates heading with the body length as its wheelbase."""


class Controller(ABC):
    """A stateful controller: ``update`` gives the next command, ``reset`` forgets the past."""

    @abstractmethod
    def update(self, *args, **kwargs) -> float: ...

    def reset(self) -> None:
        """Stateless controllers have nothing to forget."""


def sideslip_for_curvature(curvature_1pm: float, wheelbase_m: float = WHEELBASE_M) -> float:
    """Angle [rad] between the velocity and the body axis on a path of this curvature: beta = asin(kappa L / 2).

    In a steady turn the body points ``beta`` to the outside of the path, so a lateral controller compares the
    path heading ``heading + beta`` (not the body heading) with the lane's.
    """
    return math.asin(max(-0.99, min(0.99, curvature_1pm * wheelbase_m / 2)))


def steering_for_curvature(curvature_1pm: float, wheelbase_m: float = WHEELBASE_M) -> float:
    """Front-wheel angle [rad] that makes highway-env's kinematic bicycle follow a path of this curvature.

    highway-env: beta = atan(tan(delta)/2), yaw rate = v sin(beta) / (L/2), so curvature = 2 sin(beta) / L.
    """
    # invert: beta = asin(kappa L / 2), delta = atan(2 tan beta)
    return math.atan(2 * math.tan(sideslip_for_curvature(curvature_1pm, wheelbase_m)))
