"""SimWorld: one scenario run — highway-env stepping, stereo rendering, IMU, conditions, ground truth."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from percept.sensors import Frame, LandmarkMap, Pose2D, Side, StereoRig
from percept.sensors.vehicle import SIGN_PANEL_CENTRE_M

from .actors import Pedestrian, Sign
from .conditions import Condition, ConditionEffects, is_dropped
from .coords import hw_to_world_xy
from .env import PerceptEnv
from .ground_truth import GroundTruth, lane_truth, objects_truth
from .imu import ImuModel
from .render import StereoRenderer
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
    """What ``SimWorld`` simulates: the scenario, its seed, the condition and the rig."""

    scenario: str = "highway"  # a name from SCENARIOS
    seed: int = 0  # seeds the scenario's traffic and people, the textures, the IMU's noise and the condition
    condition: Condition = Condition.CLEAR  # the photometric condition applied to both cameras
    rig: StereoRig = field(default_factory=StereoRig)  # the stereo rig on the ego
    # True for rendering data sets: highway-env's IDM drives the ego instead of the actions passed to ``step``
    autopilot: bool = False
    scenery: bool = True  # roadside clutter (rails, poles, trees, buildings) on or off

    def __post_init__(self) -> None:
        check_scenario(self.scenario)
        object.__setattr__(self, "condition", check_condition(self.condition))
        if self.seed < 0:
            raise ValueError(f"seed must be >= 0, got {self.seed}")


class SimWorld:
    """Step with physical actions, observe a Frame (what the car senses) and GroundTruth (what only we know)."""

    def __init__(self, cfg: WorldConfig):
        self.cfg = cfg
        self.scenario = SCENARIOS[cfg.scenario]
        self.env = PerceptEnv(config={"scenario": self.scenario, "scenario_seed": cfg.seed,
                                      "autopilot": cfg.autopilot})
        self.env.reset(seed=cfg.seed)
        self.dt = 1.0 / self.env.config["simulation_frequency"]
        self.road_geometry = build_road_geometry(self.env.road.network)
        self.renderer = StereoRenderer(cfg.rig, self.road_geometry, seed=cfg.seed, scenery=cfg.scenery,
                                       signs_xy=self.landmark_map().positions_m[:, :2])
        self.effects = ConditionEffects(cfg.rig, cfg.condition)
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
        """The sensors' frame and the ground truth at the current step."""
        ego = self.ego
        scene = scene_from_road(self.env.road, ego, self.ids)
        rig = self.cfg.rig
        truth_imu = self.imu.true_sample(scene.ego.yaw_rad, float(ego.speed), self.dt if self.frame_index else 0.0)
        imu, wheel = self.imu.measure(truth_imu, float(ego.speed), self.dt)
        dropped = is_dropped(self.cfg.condition, self.cfg.seed, self.frame_index)
        if render:
            img = self.renderer.render(scene, emission=self.effects.reads_emission)
            left = self.effects.apply(img.left, self.cfg.seed, self.frame_index, 0, img.inv_depth[0], img.emission[0])
            right = self.effects.apply(img.right, self.cfg.seed, self.frame_index, 1, img.inv_depth[1],
                                       img.emission[1])
            depth, boxes, visible = img.depth_m, img.boxes_px, img.visible
        else:
            left = right = None
            depth = np.full((rig.camera.height, rig.camera.width), np.nan, np.float32)
            boxes, visible = {}, {}
        near = [st for st in scene.objects if _within(st.pose, scene.ego, TRUTH_RANGE_M)]
        objects = objects_truth(near, scene.ego, rig.camera, rig.cam_from_vehicle(Side.LEFT),
                                [boxes.get(st.obj_id) for st in near], [visible.get(st.obj_id, 0.0) for st in near],
                                [bool(getattr(self.ids.objects[st.obj_id], "crossing", False)) for st in near])
        ped_hit = tuple(self.ids(p) for p in self.env.road.objects
                        if isinstance(p, Pedestrian) and (p.crashed or p.hit))
        gt = GroundTruth(self.time_s, scene.ego, float(ego.speed), lane_truth(ego), objects, depth, truth_imu,
                         bool(ego.crashed), ped_hit)
        frame = Frame(self.frame_index, self.time_s, None if dropped else left, None if dropped else right, imu, wheel)
        return frame, gt

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
