"""Shared fixtures of the sims tests: the default rig and a straight 4-lane road."""

import pytest
from highway_env.road.road import RoadNetwork

from percept.sensors import StereoRig
from percept.sims.road_geometry import build_road_geometry


@pytest.fixture(scope="module")
def rig():
    return StereoRig()


@pytest.fixture(scope="module")
def road():
    return build_road_geometry(RoadNetwork.straight_road_network(4, length=400))
