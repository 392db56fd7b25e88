"""The agent: the task slots in dependency order, each timed, then the control laws on their records."""

from __future__ import annotations

import time
from dataclasses import dataclass

from percept.control import EmergencyBraking, Following, LaneChange, LaneKeeping, in_target_lane, nearer, nearest_target
from percept.sensors import BrakingRequest, EgoPath, Frame, Lead, Neighbours, PoseEstimate, Source

from .tasks import SlotContext, Task, task_order, upstream_of


@dataclass(frozen=True)
class AgentStep:
    """One step of the agent: the command, and what each slot and law made of the frame."""

    accel_mps2: float  # the commanded acceleration [m/s²]
    steering_rad: float  # the commanded front-wheel angle, ISO 8855 (positive turns left) [rad]
    estimates: dict  # task name -> the record its slot returned (or None)
    debug: dict  # task name -> its slot's debug object (or None)
    timing_ms: dict  # task name -> the wall time of its slot's step [ms]
    control: dict  # law name (lane_change, lane_keeping, following, emergency_braking) -> its debug record (the
    # lane-change law's None when lane changes are off)


class Agent:
    """Slots from the table (vision or privileged per task), and the shared laws, each fed by the record that plays
    its role, whichever task provides it: lane keeping on the ego path (``EgoPath``); following and emergency
    braking on the lead (``Lead``), the braking request (``BrakingRequest``) and a neighbour cutting in
    (``Neighbours``), at the speed of the pose estimate (``PoseEstimate``); when ``lane_changes``, the lane-change
    law on the ego path, the neighbours and the nearest target hands lane keeping its reference (a change, or a
    swerve when braking alone falls short). ValueError when no task provides the
    ego path or the pose."""

    def __init__(self, tasks: tuple[Task, ...], sources: dict, ctx: SlotContext, set_speed_mps: float,
                 lane_changes: bool = False):
        self.order = task_order(tasks)
        provided = {t.provides for t in self.order}
        for role in (EgoPath, PoseEstimate):
            if role not in provided:
                raise ValueError(f"no task provides {role.__name__}, which the control laws need")
        self.slots = {t.name: (t.vision if sources[t.name] is Source.VISION else t.privileged)(ctx)
                      for t in self.order}
        self.dt_s = ctx.dt_s
        self.keeping = LaneKeeping()
        self.following = Following(set_speed_mps)
        self.braking = EmergencyBraking()
        self.changing = LaneChange(set_speed_mps) if lane_changes else None

    def reset(self) -> None:
        """Every slot and law forgets the past."""
        for slot in self.slots.values():
            slot.reset()
        for law in (self.keeping, self.following, self.braking, self.changing):
            if law is not None:
                law.reset()

    def step(self, frame: Frame) -> AgentStep:
        """Each slot on ``frame`` in dependency order (timed), then the laws on the records they produced."""
        estimates, debug, timing, by_record = {}, {}, {}, {}
        for task in self.order:
            t0 = time.perf_counter()
            estimates[task.name], debug[task.name] = self.slots[task.name].step(frame, upstream_of(task, by_record))
            timing[task.name] = (time.perf_counter() - t0) * 1e3
            by_record[task.provides] = estimates[task.name]
        path, speed, neighbours = by_record[EgoPath], by_record[PoseEstimate].speed_mps, by_record.get(Neighbours)
        request, lead = by_record.get(BrakingRequest), by_record.get(Lead)
        ahead = nearest_target(lead, request, neighbours)
        ref, change = (self.changing.update(path, neighbours, speed, self.dt_s, ahead) if self.changing
                       else (None, None))
        steer, keeping = self.keeping.update(path, ref, self.dt_s)
        # during a change, the target lane's nearest car ahead as well
        target = nearer(ahead, in_target_lane(neighbours, change.into_lane)) if change else ahead
        follow, following = self.following.update(target, speed)
        accel, braking = self.braking.update(target, speed, follow, self.dt_s,
                                             withdrawn=request is not None and request.withdrawn)
        return AgentStep(accel, steer, estimates, debug, timing,
                         {"lane_change": change, "lane_keeping": keeping, "following": following,
                          "emergency_braking": braking})
