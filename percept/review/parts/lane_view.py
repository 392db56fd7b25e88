"""The ego lane as the neighbours part draws around the car, and the true nearest vehicle ahead and behind in each
lane that its plots set beside the estimate's.

Neighbours are reported in the ego lane's coordinates (x along it from the ego's centre, lateral from its centre
line); the review places them in the vehicle frame on the true lane (``GroundTruth.lane``), so that a track's box
sits on the true box of the vehicle it follows when its lane coordinates are right.
"""

from __future__ import annotations

import math

import numpy as np

from percept.sensors import EGO_LENGTH_M, LaneEstimate, ObjectKind, Zone

DEFAULT_LANE_WIDTH_M = 3.75
"""The lane width drawn when the truth has no lane [m] (as the neighbours slot assumes without a lane estimate)."""
LANES = (-1, 0, 1)
"""The lanes relative to the ego's: right, the ego lane, left."""


LANE_NAMES = {-1: "right", 0: "ego", 1: "left"}
"""The name of each lane's series (entity paths escape a "+")."""


def true_lane(truth) -> LaneEstimate:
    """The ego lane of ``truth`` (StepTruth) as a LaneEstimate (its centre ``centre_y(x)`` in the vehicle frame);
    a straight lane of DEFAULT_LANE_WIDTH_M along the vehicle's x axis when the truth has none."""
    lane = getattr(getattr(truth, "truth", None), "lane", None)
    if lane is None:
        return LaneEstimate(0.0, 0.0, 0.0, DEFAULT_LANE_WIDTH_M, 0.0)
    width = float(lane.width_m) if math.isfinite(lane.width_m) and lane.width_m > 0 else DEFAULT_LANE_WIDTH_M
    return LaneEstimate(float(lane.offset_m), float(lane.heading_rad), float(lane.curvature_1pm), width, 1.0)


def lane_to_vehicle(lane: LaneEstimate, x_m: np.ndarray, lat_m: np.ndarray) -> np.ndarray:
    """Points at along-lane ``x_m`` and lateral ``lat_m`` from the ego lane's centre line (N,) [m] -> vehicle-frame
    ground points (N, 3) [m], and the lane's direction there as a yaw (N,) [rad] in a fourth column."""
    x = np.asarray(x_m, dtype=float)
    # y = y_c(x) + l; the lane's direction: atan(dy_c/dx), dy_c/dx = -tan(heading) + curvature x
    y = lane.centre_y(x) + np.asarray(lat_m, dtype=float)
    yaw = np.arctan(-math.tan(lane.heading_rad) + lane.curvature_1pm * x)
    return np.column_stack([x, y, np.zeros_like(x), yaw])


def band_outline(lane: LaneEstimate, x0_m: float, x1_m: float, l0_m: float, l1_m: float, n: int = 8) -> np.ndarray:
    """A closed outline on the ground of the band x0..x1 along the lane, l0..l1 across it (2n + 1, 3) [m]."""
    x = np.linspace(x0_m, x1_m, n)
    xs = np.concatenate([x, x[::-1], x[:1]])
    ls = np.concatenate([np.full(n, l0_m), np.full(n, l1_m), [l0_m]])
    return lane_to_vehicle(lane, xs, ls)[:, :3]


def nearest_estimates(neighbours) -> dict[tuple[int, Zone], tuple[float, float]]:
    """(lane, Zone.AHEAD or Zone.BEHIND) -> (gap [m], relative speed [m/s]) of the nearest track there."""
    out: dict[tuple[int, Zone], tuple[float, float]] = {}
    for n in neighbours.tracks if neighbours is not None else ():
        key = (n.lane, n.zone)
        if n.zone is not Zone.BESIDE and (key not in out or n.gap_m < out[key][0]):
            out[key] = (n.gap_m, n.rel_speed_mps)
    return out


def nearest_truths(truth, lane: LaneEstimate, ahead_m: float, behind_m: float
                   ) -> dict[tuple[int, Zone], tuple[float, float]]:
    """The same from the true vehicles of ``truth`` (StepTruth) with centres up to ``ahead_m`` ahead and ``behind_m``
    (plus a body length) behind the ego's centre: their lane from their lateral offset from the ego lane's centre line,
    the gap bumper to bumper, the relative speed along the lane."""
    gt = truth.truth
    out: dict[tuple[int, Zone], tuple[float, float]] = {}
    for o in gt.objects:
        x, y = float(o.position_m[0]), float(o.position_m[1])
        if o.kind is not ObjectKind.VEHICLE or not -behind_m - o.size_m[0] <= x <= ahead_m:
            continue
        k = int(round(float(y - lane.centre_y(x)) / lane.width_m))
        half = (o.size_m[0] + EGO_LENGTH_M) / 2
        if abs(k) > 1 or abs(x) <= half:
            continue
        zone, gap = (Zone.AHEAD, x - half) if x > 0 else (Zone.BEHIND, -x - half)
        # along the lane: the object's yaw from the lane is yaw + heading, the ego's is heading
        rel = o.speed_mps * math.cos(o.yaw_rad + lane.heading_rad) - gt.speed_mps * math.cos(lane.heading_rad)
        if (k, zone) not in out or gap < out[(k, zone)][0]:
            out[(k, zone)] = (gap, rel)
    return out
