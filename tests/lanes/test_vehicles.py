"""A vehicle over a marking masks it: its shade found on synthetic ground (a tree's shadow is not a vehicle), then on
real frames (TuSimple 3.jpg's SUV; Udacity test5's tree shade), and TuSimple 2.jpg with that SUV pasted over its left
line, where the vehicle's own edges, not masked, pull the boundary 90 px off its markings."""

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from percept.lanes import MarkingExtractor
from percept.lanes.realworld import FootageLanes, RealLaneConfig
from percept.lanes.vehicles import VehicleBox, VehicleConfig, find_vehicles, mask_evidence
from percept.sensors import read_image

from .test_evidence_kinds import FOOTAGE, TUSIMPLE, UDACITY, Ground

TOOLS = Path(__file__).resolve().parents[2] / "tools"


def _row(g: Ground, x: float, z: float = 0.0) -> float:
    uv, _ = g.rig.project_vehicle_points(np.array([[x, 0.0, z]]))
    return float(uv[0, 1])


def _u(g: Ground, x: float, y: float) -> float:
    uv, _ = g.rig.project_vehicle_points(np.array([[x, y, 0.0]]))
    return float(uv[0, 0])


def road_with_lines(seed: int = 0) -> Ground:
    """Grey asphalt with a little grain and both ego lines (solid, 0.15 m) at +-1.85 m."""
    g = Ground((120, 120, 120))
    g.image = np.clip(g.image + np.random.default_rng(seed).normal(0, 3, g.image.shape), 0, 255).astype(np.uint8)
    for y in (1.85, -1.85):
        g.stripe(y - 0.075, y + 0.075, (235, 235, 235))
    return g


def paint_vehicle(g: Ground, x: float, y: float, width: float = 1.9) -> tuple[int, int, int]:
    """A vehicle's rear at range x centred on y: the dark shade seen under its bumper (0-0.35 m), a body of glossy
    panels (reflections: grain of 15 grey levels), trim, lights and a plate up to 1.5 m. Returns its columns and
    bottom row (u0, u1, v)."""
    u0, u1 = sorted((round(_u(g, x, y + width / 2)), round(_u(g, x, y - width / 2))))
    v_bottom, v_bumper, v_top = round(_row(g, x)), round(_row(g, x, 0.35)), round(_row(g, x, 1.5))
    img = g.image
    img[v_bumper:v_bottom, u0:u1] = 25
    img[v_top:v_bumper, u0:u1] = (60, 50, 140)  # a red body
    w = u1 - u0
    step = max((v_bumper - v_top) // 6, 1)
    img[v_bumper - step:v_bumper, u0:u1] = 30  # the bumper
    img[v_top + 2 * step:v_top + 3 * step, u0 + w // 10:u0 + w // 4] = (40, 40, 250)  # lights
    img[v_top + 2 * step:v_top + 3 * step, u1 - w // 4:u1 - w // 10] = (40, 40, 250)
    img[v_top + 3 * step:v_top + 4 * step, u0 + 2 * w // 5:u1 - 2 * w // 5] = 230  # the plate
    img[v_top:v_top + step, u0 + w // 8:u1 - w // 8] = 20  # the rear window
    img[v_top + step + 1:v_bumper - step:3, u0:u1] = 200  # chrome trim
    body = img[v_top:v_bumper, u0:u1].astype(float)
    img[v_top:v_bumper, u0:u1] = np.clip(body + np.random.default_rng(1).normal(0, 15, body.shape), 0, 255)
    return u0, u1, v_bottom


def test_a_vehicle_over_the_left_line_is_found_and_its_evidence_dropped():
    g = road_with_lines()
    u0, u1, v = paint_vehicle(g, 15.0, 1.85)
    boxes = find_vehicles(g.image, g.rig)
    assert len(boxes) == 1, boxes
    b = boxes[0]
    assert abs(b.bottom_px - (v - 1)) <= 3 and b.range_m == pytest.approx(15.0, rel=0.1)
    assert abs(b.u0_px - u0) <= 4 and abs(b.u1_px - u1) <= 4
    ev = MarkingExtractor(g.rig, FOOTAGE).extract(g.image)
    plain = MarkingExtractor(g.rig, replace(FOOTAGE, vehicles=None)).extract(g.image)
    assert ev.vehicles == (b,)
    inside = lambda e: b.covers(e.uv_px, g.rig.horizon_row, VehicleConfig.pad)  # noqa: E731
    assert inside(plain).sum() > 5 and not inside(ev).any()
    # the line in front of the vehicle stays
    assert ((np.abs(ev.points_m[:, 1] - 1.85) < 0.1) & (ev.points_m[:, 0] < 14.0)).sum() >= 20
    assert len(plain.points_m) - len(ev.points_m) == inside(plain).sum()


def test_a_tree_shadow_across_the_lane_is_not_a_vehicle():
    g = road_with_lines()
    # a shadow 1.8 m wide and 4 m deep on the lane, and a smooth dark one on the right line
    g.paint(np.array([[15.0, -0.9], [19.0, -0.9], [19.0, 0.9], [15.0, 0.9]]), (45, 45, 45))
    g.paint(np.array([[22.0, -2.8], [24.0, -2.8], [24.0, -1.0], [22.0, -1.0]]), (40, 40, 40))
    assert find_vehicles(g.image, g.rig) == []


def test_a_featureless_or_black_frame_has_no_vehicles():
    g = road_with_lines()
    assert find_vehicles(np.zeros_like(g.image), g.rig) == []
    assert find_vehicles(np.full_like(g.image, 128), g.rig) == []
    ev = MarkingExtractor(g.rig, FOOTAGE).extract(np.zeros_like(g.image))
    assert len(ev.points_m) == 0 and ev.vehicles == ()


def test_mask_evidence_without_boxes_is_the_same_evidence():
    g = road_with_lines()
    ev = MarkingExtractor(g.rig, replace(FOOTAGE, vehicles=None)).extract(g.image)
    assert mask_evidence(ev, [], g.rig.horizon_row) is ev
    far = VehicleBox(0, 5, 200, 40.0, 3.0)  # a box in the image's left corner, where no marking lies
    assert len(mask_evidence(ev, [far], g.rig.horizon_row).points_m) == len(ev.points_m)


def _still(path: Path, height_m: float = 1.642):
    if not path.exists():
        pytest.skip(f"{path} is absent (real data in ../shared/data)")
    image = read_image(path)
    return image, FootageLanes(RealLaneConfig(mount_height_m=height_m)).still(image)


def test_the_suv_in_tusimple_3_is_found():
    _, r = _still(TUSIMPLE / "3.jpg")
    # the SUV left of the ego lane: columns ~180-366, its shade's bottom row ~376 (CAR_OUTLINE_PX in the sweep)
    hits = [b for b in r.debug.evidence.vehicles if b.u0_px < 300 and b.u1_px > 250 and 365 <= b.bottom_px <= 385]
    assert len(hits) == 1, r.debug.evidence.vehicles
    b = hits[0]
    assert [b.u0_px, b.u1_px, b.bottom_px] in r.to_dict()["vehicles_px"]


def test_udacity_tree_shade_is_not_a_vehicle():
    image, r = _still(UDACITY / "test5.jpg", height_m=1.21)
    # the tree shade lies across the left half of the road (u < 800, rows 460-540); the one box is the black car
    boxes = r.debug.evidence.vehicles
    assert all(b.u0_px > 800 for b in boxes), boxes
    assert r.debug.fit.inliers_left > 100


def test_a_car_pasted_over_tusimple_2s_left_line_no_longer_pulls_the_boundary(tmp_path):
    if not (TUSIMPLE / "2.jpg").exists():
        pytest.skip(f"{TUSIMPLE / '2.jpg'} is absent (real data in ../shared/data)")
    sys.path.insert(0, str(TOOLS))
    try:
        from lanes_car_sweep import sweep
    finally:
        sys.path.remove(str(TOOLS))
    frame = read_image(TUSIMPLE / "2.jpg")
    moved = {}
    for name, cfg in (("masked", RealLaneConfig(mount_height_m=1.642)),
                      ("unmasked", RealLaneConfig(mount_height_m=1.642, lane=replace(
                          RealLaneConfig().lane, evidence=replace(FOOTAGE, vehicles=None))))):
        moved[name] = sweep(TUSIMPLE / "2.jpg", frame, FootageLanes(cfg), None, sides=("left",), ranges=(25,))
    assert moved["unmasked"] == (1, 1) and moved["masked"] == (1, 0), moved


def test_a_shades_gaps_shorter_than_the_kernel_close_and_its_runs_stay_in_place():
    from percept.lanes.vehicles import _closed

    # runs [10, 15) and [17, 22): a gap of 2 columns
    starts, ends = np.array([10, 17]), np.array([15, 22])
    assert _closed(starts, ends, 2) == [(10, 15), (17, 22)]
    assert _closed(starts, ends, 3) == [(10, 22)]
    assert _closed(np.array([], int), np.array([], int), 3) == []
