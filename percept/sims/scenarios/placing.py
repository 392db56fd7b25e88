"""Placing highway-env vehicles on a scenario's road: positions along a chain of segments, single IDM cars and
seeded traffic.

Lane changes are opt-in: a vehicle placed here keeps its lane (``enable_lane_change = False``) unless the
scenario asks for highway-env's MOBIL lane changes with ``lane_change=True``.
"""

from __future__ import annotations

from highway_env.road.road import Road
from highway_env.vehicle.behavior import IDMVehicle, LinearVehicle
from highway_env.vehicle.controller import ControlledVehicle

from .quick_road import QuickRoad


def chain_nodes(net) -> list[str]:
    """Node names of a chained network in driving order, starting at "0"."""
    order, node = ["0"], "0"
    while node in net.graph and len(order) <= len(net.graph) + 1:
        node = next(iter(net.graph[node]))
        if node == "0":
            break
        order.append(node)
    return order


def lane_at(net, lane_id: int, s: float):
    """(lane_index, longitudinal) of distance s along the chain of segments, for lane ``lane_id``."""
    nodes = chain_nodes(net)
    for a, b in zip(nodes, nodes[1:] + ["0"]):
        if b not in net.graph.get(a, {}):
            break
        lane = net.graph[a][b][lane_id]
        if s < lane.length:
            return (a, b, lane_id), s
        s -= lane.length
    raise ValueError(f"position {s:.0f} m is past the end of the road")


def new_road(env, net, connected: bool = False) -> Road:
    """A highway-env Road (QuickRoad: the same answers, faster) on ``net`` drawing from the environment's generator.
    connected: vehicles look for their neighbours on the next and previous segments too (highway-env's
    ``neighbour_vehicles_connected_lanes``), which a road of short segments needs so that traffic sees across the
    joints."""
    return QuickRoad(network=net, np_random=env.np_random, record_history=False,
                neighbour_vehicles_connected_lanes=connected)


LANE_CHANGE_TAU_LATERAL_S = 1.5
"""Lateral time constant of a lane-changing car's steering (highway-env's ControlledVehicle.TAU_LATERAL: 0.6 s) [s]."""
LANE_CHANGE_TAU_HEADING_S = 0.4
"""Heading time constant of a lane-changing car's steering (highway-env's TAU_HEADING is 0.2 s) [s]."""
LANE_CHANGE_LATERAL_SPEED_MPS = 1.0
"""The largest lateral speed a lane-changing car's steering asks for [m/s]: with the time constants above, a car
crosses the boundary about 2.3 s after it begins to move over and is within 0.2 m of its new lane's centre after
about 6 s, as drivers' lane changes last 4-6 s and more (Toledo and Zohar, "Modeling duration of lane changes", TRR
1999, 2007). highway-env's proportional law alone asks for its largest lateral speed at the start, so its car crosses
the boundary about 1.3 s after it begins to move over; with its default gains the whole change takes 1.7 s."""


class PeoplePaced:
    """Mixin over a highway-env ControlledVehicle class: it steers with ControlledVehicle's law, its lateral speed
    command, -K_p l, capped at ``LANE_CHANGE_LATERAL_SPEED_MPS``. highway-env's LinearVehicle classes (Aggressive,
    Defensive) steer with that law's linearisation at its default gains, which ignores a vehicle's own gains; they
    steer with the law itself here. A vehicle may set its own cap as ``lateral_speed_mps``."""

    lateral_speed_mps = LANE_CHANGE_LATERAL_SPEED_MPS  # the cap on its lateral speed command [m/s]

    def steering_control(self, target_lane_index) -> float:
        lateral = self.road.network.get_lane(target_lane_index).local_coordinates(self.position)[1]
        gain = self.KP_LATERAL
        # |K_p l| <= v_max  <=>  K_p <= v_max / |l|: the law runs with that gain this step
        self.KP_LATERAL = min(gain, self.lateral_speed_mps / max(abs(float(lateral)), 1e-6))
        try:
            return ControlledVehicle.steering_control(self, target_lane_index)
        finally:
            self.KP_LATERAL = gain


_PACED: dict[type, type] = {}


def people_paced(cls: type) -> type:
    """``cls`` (a highway-env ControlledVehicle class) with the lateral speed cap of ``PeoplePaced``, by the same
    name."""
    if cls not in _PACED:
        _PACED[cls] = type(cls.__name__, (PeoplePaced, cls), {"__module__": cls.__module__})
    return _PACED[cls]


def drive_like_people(v) -> None:
    """Give a lane-changing car the steering time constants ``LANE_CHANGE_TAU_LATERAL_S`` and
    ``LANE_CHANGE_TAU_HEADING_S`` (highway-env's controller reads its gains from the vehicle); ``place_idm`` gives it
    a ``people_paced`` class too."""
    # KP = 1 / tau
    v.KP_LATERAL = 1.0 / LANE_CHANGE_TAU_LATERAL_S
    v.KP_HEADING = 1.0 / LANE_CHANGE_TAU_HEADING_S


def place_idm(road, idx, s: float, speed: float, cls=IDMVehicle, lane_change: bool = False,
              paced: bool | None = None, **kw):
    """A vehicle of class ``cls`` (highway-env's IDMVehicle or a subclass) on lane ``idx`` at longitudinal s [m],
    driving at ``speed`` [m/s], which is also its target speed; lane_change: MOBIL lane changes on; paced: it changes
    lanes at a driver's pace (``people_paced``, ``drive_like_people``; by default when ``lane_change``, and for a car
    whose own script turns its lane changes on later)."""
    lane = road.network.get_lane(idx)
    paced = lane_change if paced is None else paced
    cls = people_paced(cls) if paced else cls
    v = cls(road, lane.position(s, 0.0), lane.heading_at(s), speed, target_lane_index=idx, target_speed=speed,
            **kw)
    v.enable_lane_change = lane_change
    if paced:
        drive_like_people(v)
    if isinstance(v, LinearVehicle):
        v.collecting_data = False  # its regression data would grow every step and is never read
    road.vehicles.append(v)
    return v


def place_traffic(road, rng, lanes: list[int], s0: float, s1: float, count: int, speeds: tuple[float, float],
                  keep_clear: list[tuple[int, float, float]], lane_change: bool = False) -> None:
    """``count`` IDM vehicles on ``lanes`` between s0 and s1 [m], at least 25 m apart, outside the keep-clear zones
    (lane, from, to [m]); speeds: (low, high) [m/s], drawn uniformly; lane_change: MOBIL lane changes on."""
    placed: list[tuple[int, float]] = [(ln, (a + b) / 2) for ln, a, b in keep_clear]
    tries = 0
    while count > 0 and tries < 500:
        tries += 1
        ln = int(rng.choice(lanes))
        s = float(rng.uniform(s0, s1))
        if any(ln == l2 and a - 8 <= s <= b + 8 for l2, a, b in keep_clear):
            continue
        if any(ln == l2 and abs(s - s2) < 25 for l2, s2 in placed):
            continue
        idx, ss = lane_at(road.network, ln, s)
        place_idm(road, idx, ss, float(rng.uniform(*speeds)), lane_change=lane_change)
        placed.append((ln, s))
        count -= 1
