"""The control-law base class and the kinematic-bicycle inversion used by lateral laws."""

from __future__ import annotations

import math
from abc import ABC, abstractmethod

from percept.sensors.vehicle import WHEELBASE_M


class Controller(ABC):
    """A stateful control law: ``update`` gives ``(command, debug)``, ``reset`` forgets the past.

    The debug record says which term limited the command (openpilot's controls are the model).
    """

    @abstractmethod
    def update(self, *args, **kwargs) -> tuple[float, object]: ...

    def reset(self) -> None:
        """Stateless laws have nothing to forget."""


def limiting(terms: dict[str, float | None]) -> tuple[float, str]:
    """The smallest of the named terms (None = not active) and its name; the first wins a tie."""
    name, value = None, math.inf
    for k, v in terms.items():
        if v is not None and v < value:
            name, value = k, v
    if name is None:
        raise ValueError("no active term")
    return value, name


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
