"""The scenery's grid: a frame tests only the scenery near the car, and keeps exactly what testing all of it keeps."""

import math

import numpy as np
import pytest

from percept.sensors import Pose2D
from percept.sims.render.grid import GroundGrid
from percept.sims.render.renderer import SCENERY_RANGE_M, VIEW_MARGIN_RAD, StereoRenderer
from percept.sims.render.scene import Scene


def test_the_grid_returns_every_point_inside_the_box_in_ascending_order():
    rng = np.random.default_rng(0)
    xy = rng.uniform(-500, 500, (4000, 2))
    grid = GroundGrid(xy, 50.0)
    for x0, y0, x1, y1 in [(-120, 30, 80, 260), (-500, -500, 500, 500), (10.5, 10.5, 10.6, 10.6), (-90, -3, 400, 7)]:
        got = grid.within(x0, y0, x1, y1)
        inside = np.flatnonzero((xy[:, 0] >= x0) & (xy[:, 0] <= x1) & (xy[:, 1] >= y0) & (xy[:, 1] <= y1))
        assert np.all(np.diff(got) > 0) and np.isin(inside, got).all()
        # only the cells that meet the box: nothing further than a cell from it
        dx = np.maximum(np.maximum(x0 - xy[got, 0], xy[got, 0] - x1), 0)
        dy = np.maximum(np.maximum(y0 - xy[got, 1], xy[got, 1] - y1), 0)
        assert np.all(dx <= 50.0) and np.all(dy <= 50.0)
    assert len(grid.within(900, 900, 1000, 1000)) == 0
    assert np.array_equal(grid.within(-math.inf, 0, 0, 1), np.arange(4000))
    assert len(GroundGrid(np.zeros((0, 2)), 10.0).within(0, 0, 1, 1)) == 0
    with pytest.raises(ValueError, match="cell_m must be > 0"):
        GroundGrid(xy, 0.0)


def test_the_renderer_keeps_the_same_scenery_as_testing_all_of_it(rig, road):
    r = StereoRenderer(rig, road, seed=5)
    assert len(r.scenery_centre) > 500

    def every(pose: Pose2D) -> np.ndarray:
        # the view-cone test over all the scenery, without the grid
        d = pose.to_vehicle_xy(r.scenery_centre)
        rad, x = r.scenery_radius, d[:, 0] - rig.mount_x_m
        slope = math.tan(rig.camera.hfov_rad / 2 + VIEW_MARGIN_RAD)
        return np.flatnonzero((x + rad > 0) & (x - rad < np.minimum(SCENERY_RANGE_M, r.scenery_reach))
                              & (np.abs(d[:, 1]) - rad < (x + rad) * slope + rig.baseline_m))

    rng = np.random.default_rng(1)
    kept = 0
    for x, y, yaw in zip(rng.uniform(-50, 450, 40), rng.uniform(-30, 30, 40), rng.uniform(-math.pi, math.pi, 40)):
        pose = Pose2D(float(x), float(y), float(yaw))
        got = r.scenery_in_view(Scene(pose, ()))
        assert np.array_equal(got, every(pose))  # the same float64 test on the same pieces: the same indices
        kept += len(got)
    assert kept > 0
