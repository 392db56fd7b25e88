"""SimWorld: one scenario run — highway-env stepping, stereo rendering, IMU, conditions, ground truth."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from percept.sensors import Frame, LandmarkMap, Pose2D, Side, StereoRig, rear_rig
from percept.sensors.vehicle import SIGN_PANEL_CENTRE_M

from .actors import Pedestrian, Sign
from .conditions import Condition, ConditionEffects, is_dropped
from .coords import hw_to_world_xy
from .env import PerceptEnv
from .ground_truth import CameraView, GroundTruth, collided_with, lane_truth, objects_truth
from .imu import ImuModel
from .render import RearRenderer, StereoImages, StereoRenderer, forward_twin
from .road_geometry import build_road_geometry
from .scenarios import SCENARIOS
from .snapshot import ObjectIds, scene_from_road

TRUTH_RANGE_M = 200.0


def check_scenario(name: str) -> None:
    """ValueError naming the scenarios unless ``name`` is one of them."""
    if name not in SCENARIOS:
        raise ValueError(f"unknown scenario '{name}'; choose one of: {', '.join(SCENARIOS)}")


def check_condition(name: str) -> Condition:
    """The Condition called ``name``; ValueError naming the conditions when there is none."""
    try:
        return Condition(name)
    except ValueError:
        raise ValueError(f"unknown condition '{name}'; "
                         f"choose one of: {', '.join(c.value for c in Condition)}") from None


@dataclass(frozen=True)
class WorldConfig:
    """What ``SimWorld`` simulates: the scenario, its seed, the condition and the rigs."""

    scenario: str = "highway"  # a name from SCENARIOS
    seed: int = 0  # seeds the scenario's traffic and people, the textures, the IMU's noise and the condition
    condition: Condition = Condition.CLEAR  # the photometric condition applied to both cameras
    rig: StereoRig = field(default_factory=StereoRig)  # the stereo rig on the ego
    # True for rendering data sets: highway-env's IDM drives the ego instead of the actions passed to ``step``
    autopilot: bool = False
    # with the autopilot: it also changes lanes by highway-env's own MOBIL (the anchor for lane-change progress)
    autopilot_lane_changes: bool = False
    scenery: bool = True  # roadside clutter (rails, poles, trees, buildings) on or off
    # the rear-facing rig (looking straight back, e.g. ``percept.sensors.rear_rig(rig)``), rendered beside the
    # forward one; None: the car has none
    rear_rig: StereoRig | None = None

    def __post_init__(self) -> None:
        check_scenario(self.scenario)
        object.__setattr__(self, "condition", check_condition(self.condition))
        if self.seed < 0:
            raise ValueError(f"seed must be >= 0, got {self.seed}")
        if self.rear_rig is not None:
            forward_twin(self.rear_rig)  # ValueError unless it looks straight back


def with_rear(cfg: WorldConfig, rear: bool | None) -> WorldConfig:
    """``cfg`` with the rear rig ``percept.sensors.rear_rig(cfg.rig)`` on (``rear`` True) or off (False); None keeps
    the rear rig ``cfg`` has, or puts one on where the scenario's traffic changes lanes. ValueError for anything else
    than a bool or None."""
    if rear not in (None, True, False):
        raise ValueError(f"rear must be True, False or None (the scenario's default), got {rear!r}")
    on = (cfg.rear_rig is not None or SCENARIOS[cfg.scenario].rear_by_default) if rear is None else bool(rear)
    if on and cfg.rear_rig is None:
        return replace(cfg, rear_rig=rear_rig(cfg.rig))
    if not on and cfg.rear_rig is not None:
        return replace(cfg, rear_rig=None)
    return cfg


class SimWorld:
    """Step with physical actions, observe a Frame (what the car senses) and GroundTruth (what only we know)."""

    def __init__(self, cfg: WorldConfig):
        self.cfg = cfg
        self.scenario = SCENARIOS[cfg.scenario]
        self.env = PerceptEnv(config={"scenario": self.scenario, "scenario_seed": cfg.seed,
                                      "autopilot": cfg.autopilot,
                                      "autopilot_lane_changes": cfg.autopilot_lane_changes})
        self.env.reset(seed=cfg.seed)
        self.dt = 1.0 / self.env.config["simulation_frequency"]
        self.road_geometry = build_road_geometry(self.env.road.network)
        signs_xy = self.landmark_map().positions_m[:, :2]
        self.renderer = StereoRenderer(cfg.rig, self.road_geometry, seed=cfg.seed, scenery=cfg.scenery,
                                       signs_xy=signs_xy)
        self.effects = ConditionEffects(cfg.rig, cfg.condition)
        # the rear pair: the same world (road, seed, scenery) seen looking back, under the same condition
        self.rear_renderer = None if cfg.rear_rig is None else RearRenderer(
            cfg.rear_rig, self.road_geometry, seed=cfg.seed, scenery=cfg.scenery, signs_xy=signs_xy)
        self.rear_effects = None if cfg.rear_rig is None else ConditionEffects(cfg.rear_rig, cfg.condition)
        self.imu = ImuModel(cfg.seed)
        self.ids = ObjectIds()
        self.frame_index = 0
        self.last_action = np.zeros(2)
        acc = self.env.action_type.acceleration_range
        steer = self.env.action_type.steering_range
        self.accel_range_mps2 = (float(acc[0]), float(acc[1]))
        self.steer_range_rad = (float(steer[0]), float(steer[1]))

    @property
    def ego(self):
        return self.env.vehicle

    @property
    def time_s(self) -> float:
        return self.frame_index * self.dt

    @property
    def cruise_speed_mps(self) -> float:
        return self.env.cruise_speed_mps

    def step(self, accel_mps2: float = 0.0, steering_rad: float = 0.0) -> None:
        """Advance one frame (1 / FRAME_RATE_HZ s) with a physical command, clipped to the allowed ranges.

        steering_rad is ISO 8855 (positive turns left); highway-env's positive steering turns towards its +y,
        which is to the right, so it is negated here.
        """
        a = float(np.clip(accel_mps2, *self.accel_range_mps2))
        # brakes stop the car, they do not drive it backwards
        a = max(a, -float(self.ego.speed) / self.dt)
        d = float(np.clip(steering_rad, *self.steer_range_rad))
        self.last_action = np.array([a, d])
        lo, hi = self.accel_range_mps2
        slo, shi = self.steer_range_rad
        # highway-env maps [-1, 1] linearly onto each range: x_n = 2 (x - lo) / (hi - lo) - 1
        d_hw = -d
        act = np.array([2 * (a - lo) / (hi - lo) - 1, 2 * (d_hw - slo) / (shi - slo) - 1], dtype=np.float32)
        self.env.step(act)
        self.frame_index += 1

    def observe(self, render: bool = True) -> tuple[Frame, GroundTruth]:
        """The sensors' frame and the ground truth at the current step. A dropped frame (dropout) drops both rigs'
        images."""
        ego = self.ego
        scene = scene_from_road(self.env.road, ego, self.ids)
        rig = self.cfg.rig
        truth_imu = self.imu.true_sample(scene.ego.yaw_rad, float(ego.speed), self.dt if self.frame_index else 0.0)
        imu, wheel = self.imu.measure(truth_imu, float(ego.speed), self.dt)
        dropped = is_dropped(self.cfg.condition, self.cfg.seed, self.frame_index)
        front = rear = None
        if render:
            front = self._pair(self.renderer.render(scene, emission=self.effects.reads_emission), self.effects, 0)
            if self.rear_renderer is not None:
                # the rear rig's depth map is not part of the truth: only its ids (boxes) are read
                rear = self._pair(self.rear_renderer.render(scene, emission=self.rear_effects.reads_emission,
                                                            depth=False), self.rear_effects, 2)
        if front is not None:
            depth = front[2].depth_m
        else:
            depth = np.full((rig.camera.height, rig.camera.width), np.nan, np.float32)
        gt = GroundTruth(self.time_s, scene.ego, float(ego.speed), lane_truth(ego), self._objects(scene, front, rear),
                         depth, truth_imu, bool(ego.crashed), self._pedestrians_hit(),
                         collided_with(ego, self.env.road.vehicles, self.ids, self.dt))
        left, right = (None, None) if dropped or front is None else front[:2]
        rear_left, rear_right = (None, None) if dropped or rear is None else rear[:2]
        frame = Frame(self.frame_index, self.time_s, left, right, imu, wheel, rear_left, rear_right)
        return frame, gt

    def _pair(self, img: StereoImages, effects: ConditionEffects, first_camera: int) -> tuple:
        """(left, right, img): one rig's rendered pair ``img`` with the condition applied, its cameras numbered
        ``first_camera`` and the next (their random draws)."""
        seed, k = self.cfg.seed, self.frame_index
        left = effects.apply(img.left, seed, k, first_camera, img.inv_depth[0], img.emission[0])
        right = effects.apply(img.right, seed, k, first_camera + 1, img.inv_depth[1], img.emission[1])
        return left, right, img

    def _objects(self, scene, front: tuple | None, rear: tuple | None) -> tuple:
        """The truth of the objects within TRUTH_RANGE_M, with their boxes in the rendered pairs (``_pair``'s
        results; None: not rendered)."""
        near = [st for st in scene.objects if _within(st.pose, scene.ego, TRUTH_RANGE_M)]
        rig, back_rig = self.cfg.rig, self.cfg.rear_rig
        boxes, visible = (front[2].boxes_px, front[2].visible) if front is not None else ({}, {})
        back = None
        if back_rig is not None:
            rb, rv = (rear[2].boxes_px, rear[2].visible) if rear is not None else ({}, {})
            back = CameraView(back_rig.camera, back_rig.cam_from_vehicle(Side.LEFT),
                              [rb.get(st.obj_id) for st in near], [rv.get(st.obj_id, 0.0) for st in near])
        return objects_truth(near, scene.ego, rig.camera, rig.cam_from_vehicle(Side.LEFT),
                             [boxes.get(st.obj_id) for st in near], [visible.get(st.obj_id, 0.0) for st in near],
                             [bool(getattr(self.ids.objects[st.obj_id], "crossing", False)) for st in near], back)

    def _pedestrians_hit(self) -> tuple[int, ...]:
        """Ids of the pedestrians hit so far."""
        return tuple(self.ids(p) for p in self.env.road.objects if isinstance(p, Pedestrian) and (p.crashed or p.hit))

    @property
    def pedestrians(self) -> int:
        """How many pedestrians this scenario has (crossing the road or staying on the verge)."""
        return sum(1 for o in self.env.road.objects if isinstance(o, Pedestrian))

    @property
    def crossing_pedestrians(self) -> int:
        """How many pedestrians of this scenario cross the road (the others stay on the verge)."""
        return sum(1 for o in self.env.road.objects if isinstance(o, Pedestrian) and o.crossing)

    def landmark_map(self) -> LandmarkMap:
        """Surveyed landmark signs: marker ids and panel centres in the world frame [m]."""
        out = {}
        for o in self.env.road.objects:
            if isinstance(o, Sign):
                x, y = hw_to_world_xy(o.position)
                out[o.marker_id] = [float(x), float(y), SIGN_PANEL_CENTRE_M]
        return LandmarkMap.from_dict(out)


def _within(a: Pose2D, b: Pose2D, range_m: float) -> bool:
    """Whether ``a`` lies within ``range_m`` of ``b`` on the ground: dx² + dy² <= range²."""
    dx, dy = a.x_m - b.x_m, a.y_m - b.y_m
    return not dx * dx + dy * dy > range_m ** 2
