"""highway-env's Road with the same answers at a fraction of the cost when the traffic is dense.

Every vehicle asks for its neighbours several times a step (IDM, and MOBIL for each candidate lane), and highway-env
answers each question by converting every object's position into the lane's coordinates; it also tests every pair
of objects for a collision. With 50 vehicles that is most of a simulation step. Here, during a step's decisions
(``act``, when no object moves), each lane's coordinates of every object are computed once, with highway-env's own
``local_coordinates`` and ``on_lane``, and shared by every question about that lane; the neighbour is picked by the
same rules (ties, connected segments) as highway-env's ``Road.neighbour_vehicles``. Collision tests skip the pairs
that highway-env's own spherical pre-check would turn down, calling the others in its order, so the impacts and
crashes are the same.
"""

from __future__ import annotations

import numpy as np
from highway_env.road.road import Road
from highway_env.vehicle.objects import Landmark

MARGIN_M = 0.5
"""Slack on the collision pre-filter [m]: a pair is skipped only when it is this much beyond highway-env's bound."""


class QuickRoad(Road):
    """A highway-env Road whose neighbour search and collision tests cost less (the same results)."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._tables: dict[int, tuple[np.ndarray, np.ndarray]] | None = None  # id(lane) -> (s, on): only in act

    def act(self) -> None:
        self._tables = {}
        try:
            super().act()
        finally:
            self._tables = None

    def _table(self, lane, objects: list) -> tuple[np.ndarray, np.ndarray]:
        """Longitudinal coordinate [m] of every object on ``lane`` and whether it is on it (highway-env's own
        ``on_lane`` with a 1 m margin; landmarks never are)."""
        table = self._tables.get(id(lane))
        if table is None:
            s, on = np.zeros(len(objects)), np.zeros(len(objects), bool)
            for i, o in enumerate(objects):
                if isinstance(o, Landmark):
                    continue
                s_o, lat_o = lane.local_coordinates(o.position)
                s[i], on[i] = s_o, lane.on_lane(o.position, s_o, lat_o, margin=1)
            table = self._tables[id(lane)] = (s, on)
        return table

    def _search_lanes(self, lane_index) -> list:
        """(lane, offset [m]) pairs searched for neighbours, in highway-env's order (see Road.neighbour_vehicles)."""
        lane = self.network.get_lane(lane_index)
        out = [(lane, 0.0)]
        if self.neighbour_vehicles_connected_lanes:
            _from, _to, _id = lane_index
            for next_lanes in self.network.graph.get(_to, {}).values():
                if next_lanes:
                    out.append((next_lanes[_id] if _id < len(next_lanes) else next_lanes[0], lane.length))
            for to_dict in self.network.graph.values():
                prev_lanes = to_dict.get(_from)
                if prev_lanes:
                    prev = prev_lanes[_id] if _id < len(prev_lanes) else prev_lanes[0]
                    out.append((prev, -prev.length))
        return out

    def neighbour_vehicles(self, vehicle, lane_index=None):
        if self._tables is None:
            return super().neighbour_vehicles(vehicle, lane_index)
        lane_index = lane_index or vehicle.lane_index
        if not lane_index:
            return None, None
        objects = self.vehicles + self.objects
        lane = self.network.get_lane(lane_index)
        s = lane.local_coordinates(vehicle.position)[0]
        # each object is placed on the first searched lane it is on, in that lane's coordinates plus its offset
        s_obj, placed = np.zeros(len(objects)), np.zeros(len(objects), bool)
        for search_lane, offset in self._search_lanes(lane_index):
            s_l, on = self._table(search_lane, objects)
            take = on & ~placed
            s_obj[take] = s_l[take] + offset
            placed |= take
        for i, o in enumerate(objects):
            if o is vehicle:
                placed[i] = False
        # highway-env: the front one is the nearest at s_v >= s (the last such on a tie), the rear one the nearest at
        # s_v < s (the first on a tie)
        front = np.flatnonzero(placed & (s_obj >= s))
        rear = np.flatnonzero(placed & (s_obj < s))
        v_front = objects[front[s_obj[front] == s_obj[front].min()][-1]] if len(front) else None
        v_rear = objects[rear[s_obj[rear] == s_obj[rear].max()][0]] if len(rear) else None
        return v_front, v_rear

    def step(self, dt: float) -> None:
        for vehicle in self.vehicles:
            vehicle.step(dt)
        objects = self.vehicles + self.objects
        if not objects:
            return
        pos = np.array([o.position for o in objects], float).reshape(-1, 2)
        half = np.array([o.diagonal / 2 for o in objects])
        dist = np.linalg.norm(pos[:, None, :] - pos[None, :, :], axis=2)
        n = len(self.vehicles)
        for i, vehicle in enumerate(self.vehicles):
            # highway-env's pre-check turns a pair down when |p_j - p_i| > (d_i + d_j) / 2 + v_i dt
            bound = half[i] + half + max(float(vehicle.speed), 0.0) * dt + MARGIN_M
            near = dist[i] <= bound
            for j in np.flatnonzero(near[i + 1:n]) + i + 1:
                vehicle.handle_collisions(objects[j], dt)
            for j in np.flatnonzero(near[n:]) + n:
                vehicle.handle_collisions(objects[j], dt)
