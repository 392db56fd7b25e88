"""highway-env's RoadNetwork with a spatial pre-filter for the closest-lane search.

Every vehicle asks for its closest lane every step, and highway-env answers by measuring the distance to
every lane of the network: on a winding road of ~100 lane segments that search would dominate the simulation
time. Here each lane gets a bounding circle once; only lanes whose circle comes within ``NEAR_M`` of the
position are measured. The answer is highway-env's own (same distance, same order, same tie-breaking)
whenever the closest lane is that near, and the full search runs otherwise.
"""

from __future__ import annotations

import numpy as np
from highway_env.road.road import LaneIndex, RoadNetwork

NEAR_M = 20.0
"""Lanes whose bounding circle is further than this from the position are not measured [m]."""


class IndexedRoadNetwork(RoadNetwork):
    """RoadNetwork whose ``get_closest_lane_index`` skips lanes that are far away (same answers)."""

    def __init__(self):
        super().__init__()
        self._index_size = -1

    def add_lane(self, _from: str, _to: str, lane) -> None:
        super().add_lane(_from, _to, lane)
        self._index_size = -1

    def _build_index(self) -> None:
        idx, lanes_, centres, radii = [], [], [], []
        for _from, tos in self.graph.items():
            for _to, lanes in tos.items():
                for _id, lane in enumerate(lanes):
                    s = np.append(np.arange(0.0, float(lane.length), 5.0), float(lane.length))
                    pts = np.array([lane.position(si, 0.0) for si in s])
                    c = pts.mean(axis=0)
                    idx.append((_from, _to, _id))
                    lanes_.append(lane)
                    centres.append(c)
                    # half a lane width and the 5 m sampling's chord gap on top of the farthest sample
                    radii.append(float(np.max(np.linalg.norm(pts - c, axis=1))) + lane.width_at(0.0) / 2 + 2.5)
        self._idx, self._lanes, self._centres, self._radii = idx, lanes_, np.array(centres), np.array(radii)
        self._index_size = len(idx)

    def get_closest_lane_index(self, position: np.ndarray, heading: float | None = None) -> LaneIndex:
        if self._index_size < 0:
            self._build_index()
        gap = np.linalg.norm(self._centres - np.asarray(position)[:2], axis=1) - self._radii
        near = np.flatnonzero(gap < NEAR_M)
        if len(near):
            dist = [self._lanes[i].distance_with_heading(position, heading) for i in near]
            best = int(np.argmin(dist))
            # a lane outside the filter is at least NEAR_M away, so a nearer answer is exact
            if dist[best] < NEAR_M:
                return self._idx[near[best]]
        return super().get_closest_lane_index(position, heading)
