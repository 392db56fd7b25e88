"""Vehicles among one rig's standing points: the points in lane coordinates (along the ego lane, across it from its
centre line), binned on a ground grid, and each connected group of occupied cells one vehicle, measured at the face
that looks at the rig.

A vehicle ahead shows its rear (and, in a lane beside, its inner side); one behind its front. The face nearest the
ego along the lane sets the gap, so the along-lane position of a detection is a low quantile of its points' x
(ahead; a high one behind), then the median of the points within ``face_depth_m`` of it; its lateral centre is the
middle of that face's lateral extent.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import cv2
import numpy as np

from percept.sensors import LaneEstimate

from .points import StandingPoints
from .quantiles import median, quantiles

VEHICLE_WIDTH_M = 2.0
"""The width assumed for every vehicle (highway-env's Vehicle.WIDTH): where only its side, or one edge of its face,
is seen, its centre is put half this beyond it [m]."""
VEHICLE_LENGTH_M = 5.0
"""The length assumed for every vehicle (highway-env's Vehicle.LENGTH): a camera sees one face [m]."""
DEFAULT_LANE_WIDTH_M = 3.75
"""The lane width assumed while there is no lane estimate [m]."""


@dataclass(frozen=True)
class ClusterConfig:
    """How the ground grid groups points."""

    cell_x_m: float = 1.0  # grid cell along the lane [m]
    cell_l_m: float = 0.5  # grid cell across it [m]
    min_points: int = 2  # points that make a cell occupied
    min_cells: int = 2  # cells that make a group a vehicle
    min_group_points: int = 6  # points that make a group a vehicle, far away [-]
    # ... and near by: a face of a square metre at range Z shows about (f / 2 Z)^2 points at half resolution, so a
    # group needs at least this many points times 1 / Z^2 [m^2]
    group_points_m2: float = 15000.0
    side_m: float = 0.4  # points within this of a group's inner edge are its side, not its face [m]
    side_share: float = 0.6  # a group in a lane beside with this share of its points on one line along the lane ...
    side_band_m: float = 0.2  # ... (within this of its median lateral place) is a car's side seen alone [m]
    side_reach_m: float = 20.0  # a side is seen alone only this near the ego [m]
    side_sigma_x_m: float = 2.0  # the along-lane 1-sigma of a side seen alone: one end is where the image ends [m]
    min_width_m: float = 0.4  # narrower groups are poles and the like [m]
    max_width_m: float = 3.0  # a group or face wider than this is no one vehicle: rain streaks or noise matched by
    # chance across the image, or cars run together [m]
    speckle_share: float = 0.6  # a group too wide for one vehicle is grouped again without its speckles when they
    # are under this share of its points [-]
    max_low_m: float = 0.9  # a vehicle's points reach down to this height (mismatched far background does not) [m]
    min_top_m: float = 1.0  # and, beyond side_reach_m, up to this height (a guard rail, 0.45-0.77 m, does not) [m]


@dataclass(frozen=True)
class Detection:
    """One vehicle seen by one rig this frame, in lane coordinates."""

    x_m: float  # its centre's along-lane position from the ego's centre [m] (+ ahead)
    lat_m: float  # its centre's lateral position from the ego lane's centre line [m] (+ left)
    face_x_m: float  # the along-lane position of the face the rig sees [m]
    width_m: float  # the lateral extent of that face [m]
    box_px: tuple  # (u0, v0, u1, v1) of its points in the rig's left image [px]
    points: int  # how many points it has
    sigma_x_m: float  # 1-sigma of x_m from the disparity noise [m]
    cut_off: bool = False  # the image's side edge cuts the face off: its lateral centre is inferred from one edge
    sigma_lat_m: float = 0.0  # 1-sigma of lat_m from the face's edges' pixel noise at its range [m]
    near_limit: bool = False  # the face is at the matcher's nearest depth: the car may be nearer than read


@dataclass(frozen=True)
class Face:
    """A face measured at its refined range."""

    x_m: float  # its along-lane position [m]
    sigma_x_m: float  # 1-sigma of x_m [m]
    lat_m: tuple[float, float] | None  # its lateral extent (low, high) from the ego lane's centre line, from the
    # group's points at the face's range lifted at that range; None when too few are [m]


class FaceRange(Protocol):
    """Measures a face: (the points, the indices of the face's points, the indices of its whole group) -> its
    ``Face``, or None when it cannot be measured."""

    def __call__(self, pts: StandingPoints, idx: np.ndarray, group: np.ndarray) -> Face | None: ...


def lane_coordinates(pts: StandingPoints, lane: LaneEstimate | None) -> tuple[np.ndarray, np.ndarray, float]:
    """(along, lateral, lane width): along = x; lateral = y - y_c(x), the offset from the ego lane's centre line
    (the vehicle's x axis without an estimate)."""
    if lane is None or not lane.valid:
        return pts.x, pts.y, DEFAULT_LANE_WIDTH_M
    return pts.x, pts.y - lane.centre_y(pts.x).astype(np.float32), float(lane.width_m)


def find_vehicles(pts: StandingPoints, lane: LaneEstimate | None, x_lo: float, x_hi: float, face: FaceRange,
                  cfg: ClusterConfig = ClusterConfig(), camera_height_m: float = np.inf) -> list[Detection]:
    """The vehicles among ``pts`` with centres in the ego lane or a lane beside it and faces between ``x_lo`` and
    ``x_hi`` along the lane [m], each face's range from ``face``; camera_height_m: the rig's height, which bounds what
    the band shows of a car [m]. A group too wide for a vehicle, a minority of whose points are speckles
    (``StandingPoints.speckle``), is grouped again without them: near the car, noise at night and rain streaks matched
    by chance stand up from the road, and joined to a car they make one group too wide for a vehicle (speckles are not
    dropped everywhere: a car's side, or its lamps at night, may be matched only in small patches)."""
    x, lat, width = lane_coordinates(pts, lane)
    half = 1.5 * width + 1.0
    keep = (x >= x_lo) & (x <= x_hi) & (np.abs(lat) <= half)
    def measure(g: np.ndarray) -> Detection | None:
        return _measure(pts, g, x[g], lat[g], x_lo >= 0, width, face, cfg, camera_height_m)

    out = []
    for group in _groups(x, lat, np.flatnonzero(keep), x_lo, x_hi, half, cfg):
        det = measure(group)
        if det is None and pts.speckle is not None and _joined_to_speckles(pts.speckle[group], lat[group], cfg):
            parts = [measure(g) for g in _groups(x, lat, group[~pts.speckle[group]], x_lo, x_hi, half, cfg)]
            out += [d for d in parts if d is not None]
        elif det is not None:
            out.append(det)
    return out


def _joined_to_speckles(speckle: np.ndarray, lat: np.ndarray, cfg: ClusterConfig) -> bool:
    """Whether a group's points (``speckle`` flags and lateral places ``lat`` [m], each (N,)) spread wider than one
    vehicle (their 5-95 % range) and some, fewer than ``speckle_share``, are speckles: a car joined to them (a group
    mostly of speckles is noise, and what is left of it would be noise too)."""
    if not 0 < speckle.mean() < cfg.speckle_share:
        return False
    l0, l1 = quantiles(lat, [0.05, 0.95])
    return l1 - l0 > cfg.max_width_m


def _groups(x: np.ndarray, lat: np.ndarray, idx: np.ndarray, x_lo: float, x_hi: float, half: float,
            cfg: ClusterConfig) -> list[np.ndarray]:
    """The groups of points ``idx`` (along ``x``, across ``lat``, each (N,) [m]) that may be a vehicle: each connected
    group of occupied ground-grid cells over [x_lo, x_hi] x [-half, half] with enough points for its range."""
    if len(idx) == 0:
        return []
    nx, nl = int(np.ceil((x_hi - x_lo) / cfg.cell_x_m)), int(np.ceil(2 * half / cfg.cell_l_m))
    ix = np.minimum(((x[idx] - x_lo) / cfg.cell_x_m).astype(np.int32), nx - 1)
    il = np.minimum(((lat[idx] + half) / cfg.cell_l_m).astype(np.int32), nl - 1)
    counts = np.bincount(ix * nl + il, minlength=nx * nl).reshape(nx, nl)
    occupied = (counts >= cfg.min_points).astype(np.uint8)
    n, labels = cv2.connectedComponents(occupied, connectivity=8)
    point_label = labels[ix, il]
    out = []
    for k in range(1, n):
        sel = point_label == k
        n_points = int(sel.sum())
        if n_points < cfg.min_group_points or (labels == k).sum() < cfg.min_cells:
            continue
        # N >= max(min_group_points, c / Z^2), Z the group's nearest range along the lane
        near = float(np.min(np.abs(x[idx[sel]])))
        if n_points >= cfg.group_points_m2 / max(near, 1.0) ** 2:
            out.append(idx[sel])
    return out


def _measure(pts: StandingPoints, idx: np.ndarray, x: np.ndarray, lat: np.ndarray, ahead: bool, width: float,
             face_range: FaceRange, cfg: ClusterConfig, camera_height_m: float = np.inf) -> Detection | None:
    """One group's detection, or None when it does not reach down to the road and up to a car's height, is too narrow
    or its centre is outside the three lanes. The face is what is left of the group without its inner side (the points
    within ``side_m`` of the edge nearest the ego lane's centre line, which a car in a lane beside shows along its
    length); the face's range is ``face_range`` of those points, its lateral extent runs from that inner edge to the
    face's outer edge."""
    low, top = quantiles(pts.z[idx], [0.1, 0.9])
    # near by the band holds only a car's lower part; farther, up to a little above the camera's height
    if low > cfg.max_low_m or (top < min(cfg.min_top_m, camera_height_m - 0.1)
                               and np.min(np.abs(x)) > cfg.side_reach_m):
        return None
    side = _side_view(pts, idx, x, lat, width, face_range, cfg)
    if side is not None:
        return side
    l0, l1 = quantiles(lat, [0.05, 0.95])
    if not cfg.min_width_m <= l1 - l0 <= cfg.max_width_m:
        return None
    beside = abs(0.5 * (l0 + l1)) > 0.5 * width
    # the inner edge is the one nearer the ego lane's centre line; the outer one is the face's
    inner, sign = (l0, 1.0) if l0 + l1 > 0 else (l1, -1.0)
    face = sign * (lat - inner) > cfg.side_m if beside else np.ones(len(lat), bool)
    if face.sum() < cfg.min_group_points:
        face = np.ones(len(lat), bool)
    measured = face_range(pts, idx[face], idx)
    if measured is None:
        return None
    fx, sigma = measured.x_m, measured.sigma_x_m
    if measured.lat_m is not None:
        inner, outer = measured.lat_m if sign > 0 else measured.lat_m[::-1]
    else:
        outer = quantiles(lat[face], 0.95 if sign > 0 else 0.05)
    centre_lat = float(0.5 * (inner + outer))
    if abs(centre_lat) > 1.5 * width or abs(outer - inner) > cfg.max_width_m:
        return None
    u, v = pts.u[idx], pts.v[idx]
    box = (int(u.min()), int(v.min()), int(u.max()) + 1, int(v.max()) + 1)
    centre = fx + VEHICLE_LENGTH_M / 2 if ahead else fx - VEHICLE_LENGTH_M / 2
    return Detection(centre, centre_lat, fx, float(abs(outer - inner)), box, len(idx), float(sigma))


def _side_view(pts: StandingPoints, idx: np.ndarray, x: np.ndarray, lat: np.ndarray, width: float,
               face_range: FaceRange, cfg: ClusterConfig) -> Detection | None:
    """A car in a lane beside seen only along its side (coming alongside, where the image's edge cuts its face off):
    most of the group's points lie on one line along the lane. Its centre is half a car's width beyond that line,
    away from the ego; its along-lane place is the side's, with little weight. None for any other group."""
    if np.min(np.abs(x)) > cfg.side_reach_m:  # the cheap test first: most groups are far
        return None
    mid = float(median(lat))
    if abs(mid) <= 0.5 * width or np.mean(np.abs(lat - mid) <= cfg.side_band_m) < cfg.side_share:
        return None
    on_side = np.abs(lat - mid) <= cfg.side_band_m
    measured = face_range(pts, idx[on_side], idx[on_side])
    if measured is None:
        return None
    centre_lat = mid + float(np.sign(mid)) * VEHICLE_WIDTH_M / 2
    if abs(centre_lat) > 1.5 * width:
        return None
    u, v = pts.u[idx[on_side]], pts.v[idx[on_side]]
    box = (int(u.min()), int(v.min()), int(u.max()) + 1, int(v.max()) + 1)
    return Detection(measured.x_m, centre_lat, measured.x_m, 0.0, box, int(on_side.sum()), cfg.side_sigma_x_m,
                     cut_off=True)
