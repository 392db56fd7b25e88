"""Sampled road geometry in the world frame, built once per scenario from highway-env's lanes.

The renderer never calls highway-env: it reads these arrays. Each lane of the network is sampled
along its longitudinal coordinate with ``lane.position(s, lateral)`` (highway-env's own geometry),
converted to the world frame once, here.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from highway_env.road.lane import LineType

from .coords import hw_to_world_xy

SAMPLE_STEP_M = 1.0
MARKING_WIDTH_M = 0.15
DASH_LENGTH_M = 3.0
"""US interstate broken line: 10 ft dash, 30 ft gap (MUTCD 3A.06)."""
DASH_GAP_M = 9.0
SOLID_PIECE_M = 2.0
SHOULDER_M = 1.8
EDGE_CLEAR_M = 3.0
"""A solid line with a shoulder is the road's outer edge (guard rail, poles, trees) only where no other paved
surface lies within this distance beyond the shoulder [m]."""

WHITE, YELLOW = 0, 1


@dataclass(frozen=True)
class LaneStrip:
    """One lane's paved surface: left and right edges (N, 2) in the world frame [m], including any shoulder."""

    left: np.ndarray
    right: np.ndarray


@dataclass(frozen=True)
class RoadGeometry:
    """strips: paved surface per lane; marking_quads: (Q, 4, 2) world corners [m] of marking pieces;
    marking_color: (Q,) WHITE or YELLOW; edges: list of (N, 2) outer road-edge polylines (for rails and props)
    with the outward normal side (+1 left, -1 right of travel)."""

    strips: list[LaneStrip]
    marking_quads: np.ndarray
    marking_color: np.ndarray
    edges: list[tuple[np.ndarray, int]]

    @property
    def lane_lines(self) -> list[np.ndarray]:
        """Both sides of every strip: (N, 2) world polylines [m] (what a recording draws as the road)."""
        return [s.left for s in self.strips] + [s.right for s in self.strips]


def _sample(lane, s: np.ndarray, lateral_hw: float) -> np.ndarray:
    """World positions (N, 2) of lane coordinates (s, lateral) with highway-env's own lane.position."""
    pts = np.array([lane.position(float(si), lateral_hw) for si in s])
    return hw_to_world_xy(pts)


def _line_pieces(lane, lateral_hw: float, dashed: bool) -> np.ndarray:
    """Quads (Q, 4, 2) covering one line of the lane, dashed or solid, world frame."""
    L = float(lane.length)
    if dashed:
        period = DASH_LENGTH_M + DASH_GAP_M
        starts = np.arange(0.0, L, period)
        ends = np.minimum(starts + DASH_LENGTH_M, L)
    else:
        starts = np.arange(0.0, L, SOLID_PIECE_M)
        ends = np.minimum(starts + SOLID_PIECE_M, L)
    keep = ends - starts > 0.05
    starts, ends = starts[keep], ends[keep]
    hw = MARKING_WIDTH_M / 2
    a0 = _sample(lane, starts, lateral_hw - hw)
    a1 = _sample(lane, ends, lateral_hw - hw)
    b1 = _sample(lane, ends, lateral_hw + hw)
    b0 = _sample(lane, starts, lateral_hw + hw)
    return np.stack([a0, a1, b1, b0], axis=1)


def _inside(points: np.ndarray, polygon: np.ndarray) -> np.ndarray:
    """Whether each point (M, 2) lies inside a closed polygon (V, 2), by the crossing number: a ray to +x from the
    point crosses the polygon's edges an odd number of times."""
    a, b = polygon, np.roll(polygon, -1, axis=0)
    dy = np.where(b[:, 1] == a[:, 1], 1e-12, b[:, 1] - a[:, 1])
    out = np.zeros(len(points), bool)
    for k in range(0, len(points), 256):  # in chunks: a (points, edges) table of a long lane is large
        px, py = points[k:k + 256, :1], points[k:k + 256, 1:]
        straddle = (a[None, :, 1] > py) != (b[None, :, 1] > py)
        # x where edge a->b crosses the point's row: x = ax + (py - ay) (bx - ax) / (by - ay)
        x_cross = a[None, :, 0] + (py - a[None, :, 1]) * (b[None, :, 0] - a[None, :, 0]) / dy[None, :]
        out[k:k + 256] = np.count_nonzero(straddle & (px < x_cross), axis=1) % 2 == 1
    return out


def _outer_runs(edge: np.ndarray, outward: int, polygons: list[np.ndarray], boxes: np.ndarray,
                skip: set[int]) -> list[np.ndarray]:
    """The pieces of a solid edge line that are the road's outer edge: samples with no other paved surface within
    EDGE_CLEAR_M beyond them (probed at two distances, closer than a lane is wide). polygons: every strip's outline;
    boxes: (P, 2, 2) their bounding boxes; skip: the polygons on the edge's inner side. Beside a ramp, or across
    the gore where a ramp joins, the line is a painted line between two roadways: no rail or roadside there."""
    seg = np.diff(edge, axis=0)
    normal = np.column_stack([-seg[:, 1], seg[:, 0]]) * outward
    normal /= np.linalg.norm(normal, axis=1, keepdims=True) + 1e-12
    normal = np.vstack([normal, normal[-1:]])
    probes = [edge + d * normal for d in (EDGE_CLEAR_M / 2, EDGE_CLEAR_M)]
    lo, hi = np.minimum(*[p.min(axis=0) for p in probes]), np.maximum(*[p.max(axis=0) for p in probes])
    overlap = np.flatnonzero(np.all((boxes[:, 0] <= hi) & (boxes[:, 1] >= lo), axis=1))
    blocked = np.zeros(len(edge), bool)
    for k in (k for k in overlap if k not in skip):
        for probe in probes:
            near = np.flatnonzero(~blocked & np.all((probe >= boxes[k, 0]) & (probe <= boxes[k, 1]), axis=1))
            if len(near):
                blocked[near] |= _inside(probe[near], polygons[k])
    if not blocked.any():
        return [edge]
    # runs of consecutive free samples, two samples or more
    cuts = np.flatnonzero(np.diff(np.concatenate([[0], (~blocked).astype(np.int8), [0]])))
    return [edge[i:j] for i, j in zip(cuts[::2], cuts[1::2]) if j - i >= 2]


def build_road_geometry(network) -> RoadGeometry:
    """Sample every lane of a highway-env RoadNetwork."""
    strips, quads, colors, candidates = [], [], [], []
    for _from, tos in network.graph.items():
        for _to, lanes in tos.items():
            first = len(strips)  # strips[first + i] is lane i of this segment
            for i, lane in enumerate(lanes):
                L = float(lane.length)
                n = max(int(np.ceil(L / SAMPLE_STEP_M)), 1)
                s = np.linspace(0.0, L, n + 1)
                w = float(lane.width_at(0.0))
                lt = list(lane.line_types)
                # highway-env: line_types[0] is at lateral -w/2 (left of travel), [1] at +w/2 (right)
                left_edge = lt[0] in (LineType.CONTINUOUS, LineType.CONTINUOUS_LINE)
                right_edge = lt[1] in (LineType.CONTINUOUS, LineType.CONTINUOUS_LINE)
                lat_l = -w / 2 - (SHOULDER_M if left_edge else 0.0)
                lat_r = w / 2 + (SHOULDER_M if right_edge else 0.0)
                strips.append(LaneStrip(_sample(lane, s, lat_l), _sample(lane, s, lat_r)))
                for side, lat in ((0, -w / 2), (1, w / 2)):
                    if lt[side] == LineType.NONE:
                        continue
                    q = _line_pieces(lane, lat, dashed=lt[side] == LineType.STRIPED)
                    quads.append(q)
                    # the left road edge is yellow (US convention), every other line white
                    col = YELLOW if (side == 0 and left_edge) else WHITE
                    colors.append(np.full(len(q), col, dtype=np.int8))
                # the lanes of its own segment on the inner side of each edge cannot lie beyond it
                if left_edge:
                    candidates.append((strips[-1].left, +1, set(range(first + i, first + len(lanes)))))
                if right_edge:
                    candidates.append((strips[-1].right, -1, set(range(first, first + i + 1))))
    polygons = [np.concatenate([st.left, st.right[::-1]]) for st in strips]
    boxes = np.array([[p.min(axis=0), p.max(axis=0)] for p in polygons]).reshape(-1, 2, 2)
    edges = [(run, outward) for edge, outward, skip in candidates
             for run in _outer_runs(edge, outward, polygons, boxes, skip)]
    mq = np.concatenate(quads) if quads else np.zeros((0, 4, 2))
    mc = np.concatenate(colors) if colors else np.zeros(0, dtype=np.int8)
    return RoadGeometry(strips, mq, mc, edges)
