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


def _projected_box(obj, rig, ego, side=None):
    """The box a vehicle's silhouette should have in ``side``'s image of ``rig`` (the left camera by default), with
    the ego at ``ego``: every patch of the vehicle that faces the camera, its corners projected; (box (u0, v0, u1, v1)
    [px] with u1, v1 exclusive, the corners' pixels (N, 2), their camera depths (N,) [m])."""
    import numpy as np

    from percept.sensors import Side
    from percept.sims.render import PatchBuilder
    from percept.sims.render.vehicles import vehicle_patches

    side = Side.LEFT if side is None else side
    b = PatchBuilder()
    vehicle_patches(b, obj, 0)
    p = b.build()
    cam = ego.world_from_vehicle().apply(rig.camera_position(side))
    facing = np.einsum("ij,ij->i", np.cross(p.e1, p.e2), p.origin - cam) < 0
    pts = np.concatenate([p.origin[facing], (p.origin + p.e1)[facing], (p.origin + p.e2)[facing],
                          (p.origin + p.e1 + p.e2)[facing]])
    uv, z = rig.project_vehicle_points(ego.vehicle_from_world().apply(pts), side)
    return (uv[:, 0].min(), uv[:, 1].min(), uv[:, 0].max() + 1, uv[:, 1].max() + 1), uv, z


@pytest.fixture
def projected_box():
    """``projected_box(obj, rig, ego, side=None)``: the silhouette box a vehicle should have (``_projected_box``)."""
    return _projected_box
