"""SimWorld with a rear rig: the rear pair in the Frame, its truth boxes, dropped frames, who the ego touches."""

import dataclasses

import numpy as np
import pytest

from percept.sensors import Side, StereoRig, rear_rig
from percept.sims import SCENARIOS, SimWorld, WorldConfig, with_rear
from percept.sims.conditions import Condition, is_dropped
from percept.sims.snapshot import scene_from_road

REAR = rear_rig(StereoRig())


def world(scenario: str = "highway", condition: Condition = Condition.CLEAR, rear: bool = True,
          autopilot: bool = True) -> SimWorld:
    w = SimWorld(WorldConfig(scenario, 0, condition, autopilot=autopilot, scenery=False,
                             rear_rig=REAR if rear else None))
    w.env.observation_type.observe = lambda: None  # highway-env's own observation is discarded anyway
    return w


@pytest.fixture(scope="module")
def observed():
    w = world()
    for _ in range(5):
        w.step()
    return w, *w.observe()


def test_without_a_rear_rig_the_frame_has_no_rear_pair_and_the_truth_no_rear_boxes(autopilot_world):
    frame, gt = autopilot_world("highway").observe()
    assert frame.left is not None and frame.rear_left is None and frame.rear_right is None and not frame.has_rear
    assert all(o.rear_box_px is None and o.rear_visible == 0.0 for o in gt.objects)
    assert all("rear_box_px" not in o.to_dict() for o in gt.objects)


def test_the_rear_pair_is_in_the_frame_beside_the_forward_one(observed):
    w, frame, _ = observed
    assert frame.has_rear and frame.rear_left.shape == frame.left.shape == frame.rear_right.shape
    assert frame.rear_left.dtype == np.uint8 and not np.array_equal(frame.rear_left, frame.left)
    assert frame.rear_left_gray.shape == frame.left.shape[:2]


def test_rear_truth_boxes_are_the_rear_renders_and_hold_what_is_behind(observed):
    w, _, gt = observed
    behind = [o for o in gt.objects if o.rear_box_px is not None]
    assert behind, "highway has traffic behind the ego"
    img = w.rear_renderer.render(scene_from_road(w.env.road, w.ego, w.ids))
    for o in behind:
        assert o.position_m[0] < 0 and o.box_px is None
        assert o.rear_box_px == img.boxes_px[o.obj_id]
        assert 0.0 < o.rear_visible <= img.visible[o.obj_id] + 1e-12
        # the box centre's projection by the rear rig falls in the box (a car seen whole)
        if o.rear_visible > 0.9:
            uv, _ = REAR.project_vehicle_points(np.array([o.position_m]), Side.LEFT)
            u0, v0, u1, v1 = o.rear_box_px
            assert u0 <= uv[0, 0] <= u1 and v0 <= uv[0, 1] <= v1
        assert o.to_dict()["rear_box_px"] == list(o.rear_box_px)
    assert all(o.position_m[0] > 0 for o in gt.objects if o.box_px is not None)


def test_a_dropped_frame_drops_both_rigs_images():
    w = world(condition=Condition.DROPOUT)
    k = next(i for i in range(200) if is_dropped(Condition.DROPOUT, 0, i))
    kept = next(i for i in range(k) if not is_dropped(Condition.DROPOUT, 0, i)) if k else None
    for i in range(k + 1):
        if i == kept:
            frame, _ = w.observe()
            assert frame.has_rear and not frame.dropped
        if i < k:
            w.step()
    frame, gt = w.observe()
    assert frame.dropped and frame.left is None and frame.rear_left is None and frame.rear_right is None
    assert any(o.rear_box_px is not None for o in gt.objects)  # the truth still knows what was there


def test_the_truth_names_the_vehicle_the_ego_ran_into():
    w = world("lead-brake", rear=False, autopilot=False)
    assert w.observe(render=False)[1].collided_with == ()
    for _ in range(400):
        w.step(3.0, 0.0)  # full throttle into the braking lead
        if w.ego.crashed:
            break
    _, gt = w.observe(render=False)
    lead = [o for o in gt.objects if o.kind.value == "vehicle" and abs(o.position_m[1]) < 1.0 and
            0 < o.position_m[0] < 8.0]
    assert gt.crashed and len(lead) == 1 and gt.collided_with == (lead[0].obj_id,)
    assert gt.to_dict()["collided_with"] == [lead[0].obj_id]


def test_the_rear_rig_option_and_its_checks(monkeypatch):
    cfg = WorldConfig("highway")
    assert with_rear(cfg, None).rear_rig is None and with_rear(cfg, True).rear_rig == rear_rig(cfg.rig)
    assert with_rear(with_rear(cfg, True), False).rear_rig is None
    assert with_rear(WorldConfig("highway", rear_rig=REAR), None).rear_rig == REAR
    monkeypatch.setitem(SCENARIOS, "highway", dataclasses.replace(SCENARIOS["highway"], lane_changes=True))
    assert with_rear(cfg, None).rear_rig == REAR and with_rear(cfg, False).rear_rig is None
    with pytest.raises(ValueError, match="rear must be True, False or None"):
        with_rear(cfg, "yes")
    with pytest.raises(ValueError, match="looks straight back"):
        WorldConfig("highway", rear_rig=StereoRig())
