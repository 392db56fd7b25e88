"""The road plane refined online: a camera pitched more than its calibration says makes the road ahead stand up;
the fit finds the pitch and the road lies flat again. An exact calibration is left alone."""

import dataclasses
import math

import cv2
import numpy as np
import pytest
from highway_env.road.road import RoadNetwork

from percept.longitudinal import GroundConfig, GroundPlane, ObstacleFinder
from percept.sensors import EgoPath, Pose2D, StereoRig
from percept.sims.render import Scene, StereoRenderer
from percept.sims.road_geometry import build_road_geometry


def test_plane_fit_recovers_a_pitch_and_a_height_error():
    rng = np.random.default_rng(0)
    x = rng.uniform(4, 16, 5000)
    y = rng.uniform(-5, 5, 5000)
    # road seen 1 degree nose-down off and 5 cm low: z = -0.05 + tan(1 deg) x, plus noise
    z = -0.05 + math.tan(math.radians(1.0)) * x + rng.normal(0, 0.03, 5000)
    plane = GroundPlane(GroundConfig(smoothing=1.0))
    plane.update(np.column_stack([x, y, z]), rng.uniform(0, 640, 5000))
    assert plane.active
    assert plane.offset_m == pytest.approx(-0.05, abs=0.01) and plane.slope == pytest.approx(0.01745, abs=0.001)
    h = plane.height(np.array([[30.0, 0.0, -0.05 + 30 * 0.01745 + 0.8]]))
    assert h[0] == pytest.approx(0.8, abs=0.03)


def test_a_small_misfit_stays_inside_the_deadband():
    plane = GroundPlane(GroundConfig(smoothing=1.0))
    x = np.linspace(4, 16, 2000)
    plane.update(np.column_stack([x, np.zeros_like(x), 0.002 * x]), np.linspace(0, 640, 2000))  # 6 cm at 30 m
    assert not plane.active and plane.height(np.array([[30.0, 0.0, 0.5]]))[0] == 0.5


def stereo_gray(rig: StereoRig):
    road = build_road_geometry(RoadNetwork.straight_road_network(4, length=400))
    out = StereoRenderer(rig, road, seed=3, scenery=False).render(Scene(Pose2D(100.0, -4.0, 0.0), ()))
    return [cv2.cvtColor(im, cv2.COLOR_BGR2GRAY) for im in (out.left, out.right)]


def test_an_empty_road_seen_by_a_camera_pitched_more_than_calibrated_has_no_obstacle_once_the_plane_is_fitted():
    calibrated = StereoRig()
    # the real camera looks 1.5 degrees further down than the calibration says: far road rows seem to rise
    left, right = stereo_gray(dataclasses.replace(calibrated, pitch_rad=math.radians(1.5)))
    path = EgoPath.straight(20.0)
    fixed = ObstacleFinder(calibrated, dataclasses.replace(ObstacleFinder(calibrated).cfg,
                                                           ground=GroundConfig(deadband_m=1e9)))
    ob, _ = fixed.find(left, right, path)
    assert ob is not None  # without the fit the road itself stands in the path
    finder = ObstacleFinder(calibrated)
    for _ in range(30):
        ob, _ = finder.find(left, right, path)
    assert finder.ground.active and finder.ground.slope == pytest.approx(math.tan(math.radians(1.5)), abs=0.004)
    assert ob is None
