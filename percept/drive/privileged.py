"""Privileged implementations of the task slots: they read ground truth and return the same records as the vision
slots (an ego path, a lead, a braking request, a pose). Baselines for the vision modules.

They see the truth through a ``TruthFeed`` the loop updates before every step, so that every slot has the one
interface ``reset()`` / ``step(frame, upstream) -> (estimate, debug)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from percept.sensors import BrakingRequest, EgoPath, Frame, LaneEstimate, Lead, ObjectKind, PoseEstimate
from percept.sensors.conflict import CORRIDOR_MARGIN_M, PERSON_HALF_M, person_conflict
from percept.sensors.vehicle import EGO_WIDTH_M, bumper_gap_m


class TruthFeed:
    """The current frame's ground truth, for privileged slots and scorers only (the loop sets ``truth``), and what
    stands in the true ego corridor (``ahead()``, computed once per frame for every reader)."""

    def __init__(self) -> None:
        self._truth = None
        self._ahead: list | None = None

    @property
    def truth(self):
        return self._truth

    @truth.setter
    def truth(self, gt) -> None:
        self._truth, self._ahead = gt, None

    def get(self):
        """This frame's ground truth; RuntimeError before the loop has set one."""
        if self._truth is None:
            raise RuntimeError("no ground truth yet: the loop sets it before the slots step")
        return self._truth

    def ahead(self) -> list["InPath"]:
        """``path_objects`` of the current truth."""
        if self._ahead is None:
            self._ahead = path_objects(self.get())
        return self._ahead


@dataclass(frozen=True)
class InPath:
    """An object ahead in the true ego lane's corridor, or a person about to step into it."""

    obj: object  # the ground truth's object
    gap_m: float  # free distance from the front bumper to it [m]
    vx_mps: float  # its speed along the ego's x [m/s]
    now: bool  # inside the corridor this frame
    entering: bool  # a person who will step into the corridor before the ego gets there


def true_centre_y(lane, x_m: float) -> float:
    """The true lane's centre in the vehicle frame x_m ahead [m] (``LaneTruth``)."""
    # y_c = -offset - tan(heading) x + kappa x^2 / 2
    return -lane.offset_m - math.tan(lane.heading_rad) * x_m + lane.curvature_1pm * x_m * x_m / 2


def path_objects(gt, horizon_s: float = 4.0) -> list[InPath]:
    """Objects of the ground truth ``gt`` ahead that are in the true ego lane's corridor now or (pedestrians) will
    enter it within ``horizon_s`` [s]."""
    lane = gt.lane
    out = []
    for o in gt.objects:
        if o.kind is ObjectKind.LANDMARK:
            continue
        x, y = o.position_m[0], o.position_m[1]
        if x <= 0:
            continue
        yc = true_centre_y(lane, x)
        vx = o.speed_mps * math.cos(o.yaw_rad)
        vy = o.speed_mps * math.sin(o.yaw_rad)
        if o.kind is ObjectKind.PEDESTRIAN:
            c = person_conflict(x, y, vy, yc, lane.width_m, gt.speed_mps, horizon_s)
            now, entering = c.now, c.entering
        else:
            half = o.size_m[1] / 2 if o.kind is ObjectKind.VEHICLE else PERSON_HALF_M
            now, entering = abs(y - yc) < EGO_WIDTH_M / 2 + CORRIDOR_MARGIN_M + half, False
        if now or entering:
            out.append(InPath(o, bumper_gap_m(o.distance_m), vx, now, entering))
    return out


def _nearest(items: list[InPath]) -> InPath | None:
    best = None
    for p in items:
        if best is None or p.gap_m < best.gap_m:
            best = p
    return best


@dataclass(frozen=True)
class Obstacle:
    """The nearest thing in the true ego path that the ego must respect (for scoring)."""

    gap_m: float  # free distance from the front bumper to it [m]
    speed_mps: float  # its speed along the ego's x [m/s]
    kind: ObjectKind  # what it is


def in_path_obstacle(ahead: list[InPath]) -> Obstacle | None:
    """Of ``path_objects``: the nearest vehicle in the ego lane's corridor, or pedestrian in it or entering it (what
    the ego must respect)."""
    p = _nearest([p for p in ahead if p.now or p.obj.kind is ObjectKind.PEDESTRIAN])
    return None if p is None else Obstacle(p.gap_m, p.vx_mps, p.obj.kind)


class TruthSlot:
    """A slot that reads the truth feed of its context (``ctx.truth``); stateless."""

    def __init__(self, ctx):
        self.truth: TruthFeed = ctx.truth

    def reset(self) -> None:
        """Nothing to forget."""


class PrivilegedLanes(TruthSlot):
    """The true lane as the ego path, at the true speed: its index is highway-env's lane id negated (ids count from
    the left; a change to the left adds one to the index), and the road says which lanes are beside."""

    def step(self, frame: Frame, upstream: dict) -> tuple[EgoPath, None]:
        gt = self.truth.get()
        lane = gt.lane
        return EgoPath(LaneEstimate(lane.offset_m, lane.heading_rad, lane.curvature_1pm, lane.width_m, 1.0,
                                    index=-int(lane.lane_index[2]), beside=tuple(lane.beside)), gt.speed_mps), None


class PrivilegedLongitudinal(TruthSlot):
    """The nearest object standing in the true ego corridor now, as the lead."""

    def step(self, frame: Frame, upstream: dict) -> tuple[Lead | None, None]:
        gt = self.truth.get()
        p = _nearest([p for p in self.truth.ahead() if p.now])
        if p is None:
            return None, None
        rate = p.vx_mps - gt.speed_mps
        return Lead(p.obj.distance_m, rate, p.obj.kind, 1.0, Lead.time_to_contact(p.obj.distance_m, rate),
                    p.obj.box_px, p.obj.obj_id), None


class PrivilegedPedestrians(TruthSlot):
    """A braking request for the nearest person in the true ego corridor or stepping into it."""

    def step(self, frame: Frame, upstream: dict) -> tuple[BrakingRequest | None, None]:
        gt = self.truth.get()
        p = _nearest([p for p in self.truth.ahead() if p.obj.kind is ObjectKind.PEDESTRIAN])
        if p is None:
            return None, None
        why = "pedestrian in the path" if p.now else "pedestrian stepping into the path"
        return BrakingRequest(p.obj.distance_m, p.vx_mps - gt.speed_mps, why, ObjectKind.PEDESTRIAN,
                              p.obj.obj_id), None


class PrivilegedOdometry(TruthSlot):
    """The true pose and speed, with zero covariance."""

    def step(self, frame: Frame, upstream: dict) -> tuple[PoseEstimate, None]:
        gt = self.truth.get()
        return PoseEstimate(gt.ego, gt.speed_mps, np.zeros((3, 3))), None
