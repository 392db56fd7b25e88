"""The records task slots exchange (docs/design.md, "Agent and slots"): frozen, SI units, vehicle frame unless named.

A vision slot and its privileged twin return the same record, so either can feed the control laws and the
slots downstream. Vehicle frame: ISO 8855 (x forward, y left, z up); ranges are measured from the left camera.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

import numpy as np

from .poses import Pose2D


class Source(str, Enum):
    """Where a task's estimate comes from: its vision module, or ground truth (the privileged baseline)."""

    VISION = "vision"
    PRIVILEGED = "privileged"


class ObjectKind(str, Enum):
    """What an object is, for ground truth, scoring and review."""

    VEHICLE = "vehicle"
    PEDESTRIAN = "pedestrian"
    LANDMARK = "landmark"


@dataclass(frozen=True)
class LaneEstimate:
    """The ego lane in the vehicle frame (x forward, y left), as lane keeping needs it; its centre is
    y_c(x) = -offset - tan(heading) x + curvature x^2 / 2 + curvature_rate x^3 / 6."""

    offset_m: float  # the vehicle centre's lateral offset from the lane centre [m] (+ left)
    heading_rad: float  # the vehicle's heading relative to the lane [rad] (+ counter-clockwise)
    curvature_1pm: float  # the lane's curvature [1/m] (+ turning left)
    width_m: float  # the lane's width [m]
    confidence: float  # 0..1; 0: no evidence, the values are a prediction
    valid: bool = True  # False before the first fit
    curvature_rate_1pm2: float = 0.0  # change of the curvature per metre ahead [1/m^2] (a clothoid)
    index: int = 0  # lanes the ego lane lies to the left of the first one tracked (+1 each change to the left)
    beside: tuple = (None, None)  # (left, right): is there a lane beyond that boundary: True (a broken line), False
    # (a solid line: the road's edge), None (not known)

    def lane_beside(self, side: int) -> bool | None:
        """Whether there is a lane beyond the boundary on ``side`` (+1 left, -1 right); None when not known."""
        return self.beside[0 if side > 0 else 1]

    def centre_y(self, x_m: np.ndarray) -> np.ndarray:
        """Lateral position of the lane centre at distances x_m ahead [m]."""
        x = np.asarray(x_m, dtype=float)
        # without a curvature rate its term is a signed zero wherever x^3 is finite, and so is 0 x (the same sign):
        # the power (~15 ns a value, the most of this on a frame's thousands of stereo points) is not needed
        cube = x ** 3 if self.curvature_rate_1pm2 else x
        # y_c = -offset - tan(heading) x + curvature x^2 / 2 + curvature_rate x^3 / 6
        return (-self.offset_m - np.tan(self.heading_rad) * x + 0.5 * self.curvature_1pm * x * x
                + self.curvature_rate_1pm2 * cube / 6)

    def boundary_y(self, x_m: np.ndarray, side: int) -> np.ndarray:
        """side +1: left boundary, -1: right boundary."""
        return self.centre_y(x_m) + side * self.width_m / 2

    def boundary_points_m(self, x_near_m: float, x_far_m: float, n: int = 40) -> dict[str, np.ndarray]:
        """Both boundaries on the ground: {"left"|"right": (n, 3) vehicle-frame (x, y, 0) [m]}, x_near..x_far."""
        x = np.linspace(x_near_m, x_far_m, n)
        return {name: np.column_stack([x, self.boundary_y(x, side), np.zeros_like(x)])
                for name, side in (("left", 1), ("right", -1))}


@dataclass(frozen=True)
class EgoPath:
    """Where the ego is going, as the lanes task provides it: lane keeping steers along it, and the tasks that look
    for obstacles look for them in it."""

    lane: LaneEstimate | None  # the lane it keeps (None: a straight corridor along the vehicle's x axis)
    speed_mps: float  # the speed the estimate was made with [m/s] (wheel speed for vision, true for privileged)

    @classmethod
    def straight(cls, speed_mps: float) -> "EgoPath":
        return cls(None, speed_mps)

    @property
    def follows_lane(self) -> bool:
        return self.lane is not None and self.lane.valid

    def centre_y(self, x_m: np.ndarray) -> np.ndarray:
        """Lateral position [m] of the path's centre x_m ahead (vehicle frame)."""
        return self.lane.centre_y(x_m) if self.follows_lane else np.zeros_like(np.asarray(x_m, dtype=float))


@dataclass(frozen=True)
class Lead:
    """The nearest thing standing in the ego path (a vehicle, a person, anything else that stands up)."""

    range_m: float  # left-camera depth of its nearest point [m]
    range_rate_mps: float  # d(range)/dt [m/s], negative when closing
    kind: ObjectKind = ObjectKind.VEHICLE  # what it is
    confidence: float = 1.0  # 0..1
    ttc_s: float | None = None  # time to contact [s] (None when not closing)
    box_px: tuple | None = None  # (u0, v0, u1, v1) in the left image [px], or None
    obj_id: int | None = None  # the tracker's (or the simulator's) id

    @staticmethod
    def time_to_contact(range_m: float, range_rate_mps: float) -> float | None:
        """tau = Z / -Zdot while closing; None otherwise [s]."""
        return range_m / -range_rate_mps if range_rate_mps < 0 else None


@dataclass(frozen=True)
class BrakingRequest:
    """A request to stop before a conflict point (a person stepping into the path), or to withdraw one."""

    stop_before_m: float  # left-camera range of the conflict point [m]
    range_rate_mps: float  # its d(range)/dt [m/s]
    reason: str  # why, for review
    kind: ObjectKind = ObjectKind.PEDESTRIAN  # what is there
    obj_id: int | None = None  # the tracker's (or the simulator's) id of what is there
    withdrawn: bool = False  # withdraws what was asked for obj_id (no person after all): drop a stop committed to

    @staticmethod
    def asking(request: "BrakingRequest | None") -> "BrakingRequest | None":
        """The request if it asks for braking; None when there is none or it is withdrawn."""
        return None if request is None or request.withdrawn else request


@dataclass(frozen=True)
class PoseEstimate:
    """Where the vehicle is in the world frame, and its speed."""

    pose: Pose2D  # planar pose (x_m, y_m, yaw_rad)
    speed_mps: float  # speed along the vehicle's x axis [m/s]
    covariance: np.ndarray  # (3, 3) of (x_m, y_m, yaw_rad) [m², m·rad, rad²]
    valid: bool = True  # False while the estimator has nothing to go on


@dataclass(frozen=True)
class LandmarkMap:
    """Surveyed landmark signs."""

    ids: tuple[int, ...]  # marker ids (N,)
    positions_m: np.ndarray  # their panel centres (N, 3) in the world frame [m]

    def __post_init__(self) -> None:
        p = np.asarray(self.positions_m, dtype=float).reshape(-1, 3)
        if len(p) != len(self.ids):
            raise ValueError(f"landmark map has {len(self.ids)} ids but {len(p)} positions")
        if not np.all(np.isfinite(p)):
            raise ValueError("landmark map has a non-finite position")
        object.__setattr__(self, "positions_m", p)

    def __len__(self) -> int:
        return len(self.ids)

    def position(self, marker_id: int) -> np.ndarray | None:
        """World position (3,) [m] of a marker, or None when it is not in the map."""
        try:
            return self.positions_m[self.ids.index(marker_id)]
        except ValueError:
            return None

    def to_dict(self) -> dict[str, list[float]]:
        return {str(i): [float(v) for v in p] for i, p in sorted(zip(self.ids, self.positions_m.tolist()))}

    @classmethod
    def from_dict(cls, d: dict) -> "LandmarkMap":
        items = sorted((int(k), v) for k, v in d.items())
        return cls(tuple(k for k, _ in items), np.array([v for _, v in items], dtype=float).reshape(-1, 3))



EGO_LENGTH_M = 5.0
"""The ego's length (highway-env's Vehicle.LENGTH): bumpers 2.5 m ahead of and behind its centre [m]."""


class Zone(str, Enum):
    """Where a neighbour is along the ego: wholly ahead of its front bumper, wholly behind its rear bumper, or
    overlapping it (beside)."""

    AHEAD = "ahead"
    BESIDE = "beside"
    BEHIND = "behind"


def zone_and_gap(x_m: float, length_m: float) -> tuple[Zone, float]:
    """Where a vehicle of ``length_m`` with its centre x_m ahead of the ego's lies, and the bumper gap [m] (0 beside)."""
    # ahead: its rear bumper beyond the ego's front one, x - L/2 - L_ego/2 > 0
    ahead = x_m - length_m / 2 - EGO_LENGTH_M / 2
    # behind: its front bumper short of the ego's rear one, -(x + L/2) - L_ego/2 > 0
    behind = -(x_m + length_m / 2) - EGO_LENGTH_M / 2
    if ahead > 0:
        return Zone.AHEAD, ahead
    if behind > 0:
        return Zone.BEHIND, behind
    return Zone.BESIDE, 0.0


@dataclass(frozen=True)
class Neighbour:
    """One vehicle in the ego lane or a lane beside it, ahead, beside or behind. Along-lane quantities are measured
    along the ego lane (x forward); lateral ones from the centre of the neighbour's own lane (+ left)."""

    track_id: int  # the tracker's id (the simulator's for the privileged slot)
    lane: int  # its lane relative to the ego's: -1 right, 0 the ego lane, +1 left
    zone: Zone  # ahead, beside or behind
    x_m: float  # its centre's along-lane position from the ego's centre [m] (+ ahead)
    gap_m: float  # bumper to bumper [m]: ahead its rear to the ego's front, behind the ego's rear to its front; 0 beside
    rel_speed_mps: float  # d(x_m)/dt [m/s]: its speed less the ego's (+ pulling ahead)
    lateral_m: float  # its centre's offset from the centre of its lane [m] (+ left)
    lateral_speed_mps: float  # d(lateral_m)/dt [m/s] (+ left)
    length_m: float = EGO_LENGTH_M  # its length [m]
    sigma_x_m: float = 0.0  # 1-sigma of x_m (and so of gap_m) [m]
    sigma_rel_speed_mps: float = 0.0  # 1-sigma of rel_speed_mps [m/s]
    sigma_lateral_m: float = 0.0  # 1-sigma of lateral_m [m]
    camera: str | None = None  # "front" or "rear": the rig that measured it this frame (None: predicted only)
    box_px: tuple | None = None  # (u0, v0, u1, v1) in that rig's left image [px], or None
    cut_in: bool = False  # its lateral motion will take it across the boundary into the ego lane (or, in the ego
    # lane, it came in so, and stays flagged while it is tracked there)
    time_to_cross_s: float | None = None  # predicted time until its centre reaches that boundary [s] (cut-ins only; 0
    # once across)

    @property
    def predicted(self) -> bool:
        """Whether no camera measured it this frame (in the blind zone beside the ego, or missed)."""
        return self.camera is None


@dataclass(frozen=True)
class Neighbours:
    """Every tracked vehicle within bumper gaps of ``ahead_m`` ahead and ``behind_m`` behind in the ego lane and the
    lanes either side, as the neighbours task provides it."""

    tracks: tuple[Neighbour, ...]  # nearest first within each lane
    ahead_m: float = 80.0  # how far ahead the lanes are covered [m]
    behind_m: float = 85.0  # how far behind: a lane change must see a follower closing fast long before it arrives,
    # and the rear rig's points reach 90 m of camera depth [m]
    rear: bool = True  # whether the rear rig saw this frame (False: behind is covered by prediction only)

    def in_lane(self, lane: int) -> tuple[Neighbour, ...]:
        """The tracks in ``lane`` (-1, 0, +1), nearest first."""
        return tuple(n for n in self.tracks if n.lane == lane)

    def lane_free(self, lane: int, behind_m: float, ahead_m: float) -> bool:
        """Whether no track (measured or predicted) may lie in ``lane`` with its centre between ``behind_m`` behind and
        ``ahead_m`` ahead of the ego's centre, widened by three sigma of its position: a lane is never free while a
        track may be in it."""
        return not any(n.lane == lane and -behind_m - 3 * n.sigma_x_m <= n.x_m <= ahead_m + 3 * n.sigma_x_m
                       for n in self.tracks)

    def nearest(self, lane: int, zone: Zone) -> Neighbour | None:
        """The nearest track in ``lane`` (-1, 0, +1) and ``zone``; None when there is none."""
        return next((n for n in self.tracks if n.lane == lane and n.zone is zone), None)

    def cutting_in(self) -> Neighbour | None:
        """The nearest neighbour ahead flagged as cutting in (the following law treats it as a lead before it arrives,
        and until the lead's own slot takes it up); None when none is."""
        ahead = [n for n in self.tracks if n.cut_in and n.zone is Zone.AHEAD]
        return min(ahead, key=lambda t: t.gap_m) if ahead else None
