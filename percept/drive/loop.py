"""The closed loop: observe -> slots (timed) -> control laws -> score -> record -> step, and the run JSON."""

from __future__ import annotations

import time
from typing import Callable

from percept.control import Phase
from percept.sensors import Source
from percept.sims import SimWorld
from percept.sims.coords import hw_pose

from .agent import Agent
from .config import DriveConfig
from .lane_change_scoring import LaneChangeScorer, ProgressScorer
from .privileged import TruthFeed, in_path_obstacle
from .scoring import SafetyScorer, ScoreContext, StepTruth
from .tasks import SlotContext


def run_drive(cfg: DriveConfig, recorder_factory=None, progress: Callable[[int, int], None] | None = None,
              render: bool = True) -> dict:
    """Drive one run; returns the run JSON (docs/design.md, "The run JSON": one group per task).

    ``recorder_factory(world)`` returns an object with ``log_step(frame, step_truth, agent_step)``.
    ``render=False`` skips the cameras: only possible while every slot is privileged (baselines, fast tests).
    """
    if cfg.needs_cameras and not render:
        raise ValueError("vision slots need the cameras (render=True)")
    world = SimWorld(cfg.world)
    feed = TruthFeed()
    agent = Agent(cfg.tasks, cfg.sources, slot_context(world, feed, cfg.detector), world.cruise_speed_mps,
                  cfg.lane_changes)
    rig = world.cfg.rig
    scorers = {t.name: t.scorer(ScoreContext(cfg.source(t.name) is Source.VISION, world.pedestrians,
                                             world.crossing_pedestrians, agent.following.time_gap,
                                             rig.camera.fx * rig.baseline_m, cfg.detector))
               for t in cfg.tasks}
    safety, pace = SafetyScorer(), ProgressScorer(world.cruise_speed_mps, world.dt)
    changes = LaneChangeScorer(world.dt, cfg.lane_changes)
    recorder = recorder_factory(world) if recorder_factory else None
    duration = cfg.duration_s if cfg.duration_s is not None else world.scenario.duration_s
    n = max(int(round(duration / world.dt)), 1)
    slot_ms = {t.name: 0.0 for t in cfg.tasks}
    render_ms, frames, t_start = 0.0, 0, time.perf_counter()
    for i in range(n):
        t0 = time.perf_counter()
        frame, gt = world.observe(render=render)
        render_ms += (time.perf_counter() - t0) * 1e3
        feed.truth = gt
        step = agent.step(frame)
        ahead = feed.ahead()
        change = step.control["lane_change"]
        # the boundary a commanded change crosses, or any that highway-env's MOBIL in the ego's place crosses, is no
        # departure
        side = change.side if change is not None and change.phase is not Phase.KEEP else (
            0 if cfg.world.autopilot_lane_changes else None)
        truth = StepTruth(gt, ahead, in_path_obstacle(ahead), step.accel_mps2, step.steering_rad, side)
        safety.update(truth)
        pace.update(gt)
        changes.update(gt, change)
        for name, scorer in scorers.items():
            scorer.update(step.estimates[name], step.debug[name], truth)
            slot_ms[name] += step.timing_ms[name]
        if recorder is not None:
            recorder.log_step(frame, truth, step)
        world.step(step.accel_mps2, step.steering_rad)
        frames += 1
        if progress:
            progress(i + 1, n)
    wall = time.perf_counter() - t_start
    sim_s = frames * world.dt
    result = {"scenario": cfg.world.scenario, "condition": cfg.world.condition.value, "seed": cfg.world.seed,
              "duration_s": round(sim_s, 4), "frames": frames, "realtime_factor": sim_s / wall if wall > 0 else None,
              "slots": {name: src.value for name, src in cfg.sources.items()}, "rear": cfg.rear,
              "lane_changes_on": cfg.lane_changes, **safety.result(changes.counts["unsafe"]), "progress": pace.result(),
              "lane_changes": changes.result(), "evasive": changes.evasive_result()}
    result.update({t.name: scorers[t.name].result() for t in cfg.tasks})
    result["timing_ms"] = timing_json(cfg, slot_ms, render_ms if render else None, frames)
    return result


def slot_context(world: SimWorld, feed: TruthFeed, detector: str = "sim") -> SlotContext:
    """What the slots of a run in ``world`` may use: its rig and frame period, its landmark map (None on a road
    without signs), the truth ``feed``, the people model ``detector``, the ego's start pose and the rear rig (None
    when the car has none)."""
    lm = world.landmark_map()
    return SlotContext(world.cfg.rig, world.dt, lm if len(lm) else None, feed, detector, hw_pose(world.ego),
                       world.cfg.rear_rig)


def timing_json(cfg: DriveConfig, slot_ms: dict, render_ms: float | None, frames: int) -> dict:
    """Per-frame cost [ms] of rendering and of each vision slot (None for privileged ones), and their sum."""
    per = {t.name: slot_ms[t.name] / max(frames, 1) if cfg.source(t.name) is Source.VISION else None
           for t in cfg.tasks}
    vision = [v for v in per.values() if v is not None]
    return {"render": None if render_ms is None else render_ms / max(frames, 1), **per,
            "perception_total": sum(vision) if vision else None}
