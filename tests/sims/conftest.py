"""Shared fixtures of the sims tests: the default rig, a straight 4-lane road, and scenario worlds and environments
with the autopilot ego."""

import pytest
from highway_env.road.road import RoadNetwork

from percept.sensors import StereoRig
from percept.sims import SCENARIOS, SimWorld, WorldConfig
from percept.sims.env import PerceptEnv
from percept.sims.road_geometry import build_road_geometry


@pytest.fixture(scope="module")
def rig():
    return StereoRig()


@pytest.fixture(scope="module")
def road():
    return build_road_geometry(RoadNetwork.straight_road_network(4, length=400))


def _autopilot_world(name: str, seed: int = 0, fast: bool = True) -> SimWorld:
    w = SimWorld(WorldConfig(name, seed, autopilot=True, scenery=False))
    if fast:
        # SimWorld discards highway-env's own Kinematics observation, which costs about 2/3 of a step (pandas);
        # it draws no random numbers, so skipping it changes nothing else
        w.env.observation_type.observe = lambda: None
    return w


def _scenario_env(name: str, seed: int) -> PerceptEnv:
    e = PerceptEnv(config={"scenario": SCENARIOS[name], "scenario_seed": seed, "autopilot": True})
    e.reset(seed=seed)
    return e


@pytest.fixture(scope="session")
def autopilot_world():
    """``autopilot_world(name, seed=0, fast=True)``: the scenario's SimWorld without scenery, the ego on
    highway-env's autopilot; ``fast`` skips highway-env's unused observation."""
    return _autopilot_world


@pytest.fixture(scope="session")
def scenario_env():
    """``scenario_env(name, seed)``: the highway-env side of a scenario alone (no renderer), reset with ``seed``."""
    return _scenario_env
