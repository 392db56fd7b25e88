"""The closed loop: simulator frame -> agent -> action -> simulator, scored and optionally recorded."""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from enum import Enum
from typing import Callable

import numpy as np

from percept.control import LaneKeeping
from percept.lanes import LaneDetector
from percept.sims import SimWorld, WorldConfig
from percept.sims.actors import Pedestrian

from .privileged import PrivilegedLateral, PrivilegedLongitudinal, in_path_obstacle
from .scoring import RunScorer


class Mode(str, Enum):
    VISION = "vision"
    PRIVILEGED = "privileged"


SLOTS = ("lateral", "longitudinal", "pedestrians", "odometry")
VISION_SLOTS = ("lateral",)


@dataclass(frozen=True)
class DriveConfig:
    """world: scenario, seed, condition, rig; duration_s: None = the scenario's default; slots: Mode per task."""

    world: WorldConfig = field(default_factory=WorldConfig)
    duration_s: float | None = None
    lateral: Mode = Mode.PRIVILEGED
    longitudinal: Mode = Mode.PRIVILEGED
    pedestrians: Mode = Mode.PRIVILEGED
    odometry: Mode = Mode.PRIVILEGED

    def __post_init__(self) -> None:
        if self.duration_s is not None and not self.duration_s > 0:
            raise ValueError(f"--duration must be positive, got {self.duration_s}")
        for slot in SLOTS:
            try:
                mode = Mode(getattr(self, slot))
            except ValueError:
                raise ValueError(f"--{slot} must be vision or privileged, got '{getattr(self, slot)}'") from None
            object.__setattr__(self, slot, mode)
            if mode is Mode.VISION and slot not in VISION_SLOTS:
                raise ValueError(f"the {slot} slot has no vision implementation yet; use --{slot} privileged")

    @property
    def needs_cameras(self) -> bool:
        """Whether any slot reads the camera images."""
        return any(getattr(self, slot) is Mode.VISION for slot in SLOTS)


def run_drive(cfg: DriveConfig, recorder_factory=None, progress: Callable[[int, int], None] | None = None,
              render: bool = True) -> dict:
    """Drive one run; returns the run JSON (DESIGN.md contract).

    ``recorder_factory(world)`` returns an object with ``log_step(t, frame, gt, action, lead_gap_m)`` and
    ``log_lanes(estimate, debug)`` (optional).
    ``render=False`` skips the cameras: only possible while every slot is privileged (baselines, fast tests).
    """
    world = SimWorld(cfg.world)
    recorder = recorder_factory(world) if recorder_factory else None
    duration = cfg.duration_s if cfg.duration_s is not None else world.scenario.duration_s
    n = max(int(round(duration / world.dt)), 1)
    lateral = PrivilegedLateral()
    vision_lateral = cfg.lateral is Mode.VISION
    if vision_lateral and not render:
        raise ValueError("the vision lateral slot needs the cameras (render=True)")
    lanes = LaneDetector(world.cfg.rig) if vision_lateral else None
    keeping = LaneKeeping()
    lane_err, lanes_ms = [], 0.0
    longitudinal = PrivilegedLongitudinal(world.cruise_speed_mps)
    scorer = RunScorer()
    has_crossing = any(isinstance(o, Pedestrian) and o.crossing for o in world.env.road.objects)
    render_ms = 0.0
    t_start = time.perf_counter()
    frames = 0
    for i in range(n):
        t0 = time.perf_counter()
        frame, gt = world.observe(render=render)
        render_ms += (time.perf_counter() - t0) * 1e3
        obstacle = in_path_obstacle(gt)
        if lanes is not None:
            t0 = time.perf_counter()
            est, lanes_debug = lanes.process(frame.left, frame.wheel_speed_mps, frame.imu.yaw_rate_rps, world.dt)
            lanes_ms += (time.perf_counter() - t0) * 1e3
            steer = keeping.update(est.offset_m, est.heading_rad, est.curvature_1pm, frame.wheel_speed_mps)
            if est.valid:
                lane_err.append([est.offset_m - gt.lane.offset_m, est.heading_rad - gt.lane.heading_rad,
                                 est.curvature_1pm - gt.lane.curvature_1pm])
        else:
            steer = lateral.update(gt.lane, gt.speed_mps)
        accel = longitudinal.update(obstacle, gt.speed_mps)
        hit = [world.ids(p) for p in world.env.road.objects if isinstance(p, Pedestrian) and (p.crashed or p.hit)]
        scorer.update(gt, obstacle, hit)
        if recorder is not None:
            recorder.log_step(gt.time_s, frame, gt, world.last_action, obstacle.gap_m if obstacle else None)
            if lanes is not None:
                recorder.log_lanes(est, lanes_debug)
        world.step(accel, steer)
        frames += 1
        if progress:
            progress(i + 1, n)
    wall = time.perf_counter() - t_start
    s = scorer.result(has_crossing)
    lanes_per_frame = lanes_ms / max(frames, 1) if lanes is not None else None
    sim_s = frames * world.dt
    return {
        "scenario": cfg.world.scenario,
        "condition": cfg.world.condition.value,
        "seed": cfg.world.seed,
        "duration_s": round(sim_s, 4),
        "frames": frames,
        "realtime_factor": sim_s / wall if wall > 0 else None,
        "slots": {slot: getattr(cfg, slot).value for slot in SLOTS},
        "collisions": s["collisions"],
        "pedestrian_collisions": s["pedestrian_collisions"],
        "lane_departures": s["lane_departures"],
        "lane": {**_rmse(lane_err, ("offset_rmse_m", "heading_rmse_rad", "curvature_rmse_1pm")),
                 "centering_rms_m": s["centering_rms_m"], "centering_max_m": s["centering_max_m"]},
        "longitudinal": {"range_abs_rel_err": None, "range_abs_rel_err_by_bin": None, "ttc_abs_err_s": None,
                         "time_gap_mean_s": s["time_gap_mean_s"], "time_gap_min_s": s["time_gap_min_s"],
                         "time_gap_steady_s": s["time_gap_steady_s"],
                         "time_gap_setting_s": longitudinal.time_gap},
        "pedestrians": {"recall": None, "precision": None, "fppi": None, "first_detection_range_m": None,
                        "stops": s["stops"], "false_stops": s["false_stops"]},
        "odometry": {"drift_pct_vo": None, "drift_pct_fused": None, "ate_rmse_vo_m": None, "ate_rmse_fused_m": None,
                     "landmark_fixes": None},
        "timing_ms": {"render": render_ms / max(frames, 1) if render else None, "lanes": lanes_per_frame,
                      "longitudinal": None, "pedestrians": None, "odometry": None,
                      "perception_total": lanes_per_frame},
    }


def _rmse(errors: list, keys: tuple) -> dict:
    """RMS of each column of the per-frame errors; None (does not apply) without estimates."""
    if not errors:
        return {k: None for k in keys}
    e = np.asarray(errors, dtype=float)
    return {k: float(v) for k, v in zip(keys, np.sqrt(np.mean(e * e, axis=0)))}
