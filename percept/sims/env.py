"""PerceptEnv: a highway-env environment whose scene comes from a percept scenario.

It keeps highway-env's own machinery (road, IDM traffic, the ego's kinematic bicycle model, collision
handling, the continuous action) and adds what highway-env lacks: pedestrians that walk, scripted
vehicles, and an optional autopilot ego for rendering data sets.
"""

from __future__ import annotations

import numpy as np
from gymnasium import spaces
from highway_env.envs.common.abstract import AbstractEnv
from highway_env.envs.common.observation import ObservationType
from highway_env.vehicle.behavior import IDMVehicle

from percept.sensors.frame import FRAME_RATE_HZ
from percept.sensors.vehicle import ACCEL_RANGE_MPS2, STEER_RANGE_RAD

from .actors import Pedestrian, ScriptedVehicle


class NoObservation(ObservationType):
    """percept's agent sees only the cameras (rendered by SimWorld), so highway-env computes no observation: its
    Kinematics table would cost more than the rest of a simulation step."""

    def space(self) -> spaces.Space:
        return spaces.Box(0.0, 0.0, shape=(0,), dtype=np.float32)

    def observe(self) -> np.ndarray:
        return np.zeros(0, dtype=np.float32)


class AutopilotVehicle(IDMVehicle):
    """highway-env's IDM car (changing lanes by its MOBIL where enabled) that brakes to a standstill but never
    reverses."""

    def step(self, dt: float) -> None:
        super().step(dt)
        self.speed = max(self.speed, 0.0)


class PerceptEnv(AbstractEnv):
    """Config keys beyond highway-env's: ``scenario`` (a Scenario), ``scenario_seed`` (int), ``autopilot`` (bool),
    ``autopilot_lane_changes`` (bool: the autopilot changes lanes by MOBIL)."""

    @classmethod
    def default_config(cls) -> dict:
        cfg = super().default_config()
        cfg.update({
            "observation": {"type": "Kinematics"},  # replaced by NoObservation in define_spaces
            "action": {"type": "ContinuousAction", "acceleration_range": ACCEL_RANGE_MPS2,
                       "steering_range": STEER_RANGE_RAD, "clip": True},
            "simulation_frequency": FRAME_RATE_HZ,
            "policy_frequency": FRAME_RATE_HZ,
            "screen_width": 640,
            "screen_height": 480,
            "scenario": None,
            "scenario_seed": 0,
            "autopilot": False,
            "autopilot_lane_changes": False,
        })
        return cfg

    def define_spaces(self) -> None:
        super().define_spaces()
        self.observation_type = NoObservation(self)
        self.observation_space = self.observation_type.space()

    def _reset(self) -> None:
        scenario = self.config["scenario"]
        if scenario is None:
            raise ValueError("PerceptEnv needs config['scenario']")
        rng = np.random.default_rng(self.config["scenario_seed"])
        # highway-env's own random draws (IDM behaviour) follow the scenario seed too
        self.road = scenario.build(self, rng)
        # AbstractEnv.reset sets the road's neighbour search from the config after this: keep the scenario's own
        self.config["neighbour_vehicles_connected_lanes"] = self.road.neighbour_vehicles_connected_lanes
        if not self.config["autopilot"] or self.config["autopilot_lane_changes"]:
            # MOBIL weighs the braking a lane change imposes on the new follower at the follower's target speed: the
            # ego's is its set speed (highway-env's kinematic Vehicle has none, and IDM would read none as 0 m/s);
            # highway-env's MOBIL car in the ego's place, the anchor for progress, wants that speed too
            self.vehicle.target_speed = self.cruise_speed_mps
        self.pedestrians = [o for o in self.road.objects if isinstance(o, Pedestrian)]
        self.scripted = [v for v in self.road.vehicles if isinstance(v, ScriptedVehicle)]

    def make_ego(self, lane_index, longitudinal: float, speed: float):
        """The controlled vehicle: highway-env's kinematic Vehicle, or an IDM autopilot (keeping its lane, or changing
        lanes by MOBIL with ``autopilot_lane_changes``)."""
        lane = self.road.network.get_lane(lane_index)
        pos, heading = lane.position(longitudinal, 0.0), lane.heading_at(longitudinal)
        if self.config["autopilot"]:
            ego = AutopilotVehicle(self.road, pos, heading, speed, target_lane_index=lane_index, target_speed=speed,
                             enable_lane_change=bool(self.config["autopilot_lane_changes"]))
        else:
            ego = self.action_type.vehicle_class(self.road, pos, heading, speed)
        self.cruise_speed_mps = float(speed)
        self.controlled_vehicles = [ego]
        self.road.vehicles.insert(0, ego)
        return ego

    def _simulate(self, action=None) -> None:
        frames = int(self.config["simulation_frequency"] // self.config["policy_frequency"])
        dt = 1.0 / self.config["simulation_frequency"]
        for _ in range(frames):
            if action is not None and not self.config["autopilot"]:
                self.action_type.act(action)
            t = self.steps * dt
            for v in self.scripted:
                v.script(t, self.vehicle)
            self.road.act()
            self.road.step(dt)
            for p in self.pedestrians:
                p.update(dt, self.vehicle.position[0])
            self.steps += 1
        self.enable_auto_render = False

    def _reward(self, action) -> float:
        return 0.0

    def _is_terminated(self) -> bool:
        return False

    def _is_truncated(self) -> bool:
        return False
