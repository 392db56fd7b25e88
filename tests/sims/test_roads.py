"""The scenarios' roads: the curves' arcs and clothoids and the ground truth's curvature along them, the loop's
closed circuit and its landmark signs, the indexed road network, and the signs kept from frame to frame."""

import types

import numpy as np
import pytest
from highway_env.road.lane import CircularLane

from percept.sims import SimWorld, WorldConfig
from percept.sims.actors import Sign
from percept.sims.coords import world_to_hw_xy
from percept.sims.ground_truth import lane_truth
from percept.sims.road_geometry import SHOULDER_M
from percept.sims.scenarios import ClothoidLane, winding_road
from percept.sims.scenarios.placing import chain_nodes as _chain


def segments(net, lane_id: int):
    nodes = _chain(net)
    return [net.graph[a][b][lane_id] for a, b in zip(nodes, nodes[1:] + ["0"]) if b in net.graph.get(a, {})]


def probe(net, lane, s: float):
    """A stand-in ego on ``lane`` of ``net`` at ``s`` along it, as ``lane_truth`` reads one."""
    position = lane.position(s, 0.0)
    return types.SimpleNamespace(lane=lane, position=position, heading=lane.heading_at(s),
                                 lane_index=net.get_closest_lane_index(position), road=types.SimpleNamespace(network=net))


def test_curves_radii_and_curvature_sign_of_every_arc(scenario_env):
    for seed in range(3):
        e = scenario_env("curves", seed)
        net = e.road.network
        arcs = [lane for tos in net.graph.values() for lanes in tos.values() for lane in lanes
                if isinstance(lane, CircularLane)]
        radii = np.array([lane.radius for lane in arcs])
        assert len(arcs) > 10 and np.all((radii >= 150.0) & (radii <= 600.0)), (seed, radii.min(), radii.max())
        assert {a.clockwise for a in arcs} == {True, False}
        # ground truth at the middle of each arc of the ego lane: curvature = +1/r turning left (world frame);
        # highway-env's clockwise arcs (y down) turn right
        for lane in segments(net, 1):
            s = lane.length / 2
            k = lane_truth(probe(net, lane, s)).curvature_1pm
            if isinstance(lane, CircularLane):
                expect = (-1.0 if lane.clockwise else 1.0) / lane.radius
            elif isinstance(lane, ClothoidLane):
                expect = -lane.curvature_at(s)
            else:
                expect = 0.0
            assert k == pytest.approx(expect, rel=1e-3, abs=1e-6)  # [1/m]: a straight is a radius over 1000 km
        e.close()


def test_curves_curvature_is_continuous_through_clothoid_transitions(scenario_env):
    """No curvature steps: along the ego lane, the truth changes by at most the steepest spiral's rate x 1 m."""
    e = scenario_env("curves", 0)
    lanes = segments(e.road.network, 1)
    assert any(isinstance(lane, ClothoidLane) for lane in lanes)
    ks = []
    for lane in lanes:
        for s in np.arange(0.0, lane.length, 1.0):
            ks.append(lane_truth(probe(e.road.network, lane, s)).curvature_1pm)
    # steepest spiral: 1/150 m over 50 m (reverse curves: 2/150 over 100 m); with 1 m steps and the ±1 m
    # central difference, one sample may straddle a join
    assert np.max(np.abs(np.diff(ks))) < 2.5 * (1 / 150) / 50
    e.close()


def test_clothoid_lane_round_trip_and_arc_length():
    lane = ClothoidLane(np.array([10.0, -5.0]), 0.3, 60.0, 0.0, 1 / 150, offset_m=8.0, width=4.0)
    rng = np.random.default_rng(0)
    for s, r in zip(rng.uniform(-5, lane.length + 5, 50), rng.uniform(-3, 3, 50)):
        s2, r2 = lane.local_coordinates(lane.position(s, r))
        assert (s2, r2) == pytest.approx((s, r), abs=1e-5)
    pts = np.array([lane.position(s, 0.0) for s in np.linspace(0, lane.length, 3001)])
    assert np.sum(np.linalg.norm(np.diff(pts, axis=0), axis=1)) == pytest.approx(lane.length, abs=1e-3)
    # heading at the end: theta0 + (k0 + k1) L / 2, whatever the offset
    assert lane.heading_at(lane.length) == pytest.approx(0.3 + 60.0 / 300.0, abs=1e-9)  # [rad]
    # the offset lane inside the turn is shorter: ds = (1 - offset k) du
    assert lane.length == pytest.approx(60.0 - 8.0 * 60.0 / 300.0, abs=1e-6)  # [m]
    with pytest.raises(ValueError, match="positive length"):
        ClothoidLane(np.zeros(2), 0.0, 0.0, 0.0, 0.01)


def test_curves_closed_loop_curvature_takes_both_signs_and_matches_yaw_rate(autopilot_world):
    w = autopilot_world("curves")
    # traffic plays no part here; without it a step is ~10x cheaper (highway-env searches every lane per vehicle)
    del w.env.road.vehicles[1:]
    rows = []
    for _ in range(600):
        w.step()
        _, gt = w.observe(render=False)
        rows.append((gt.lane.curvature_1pm, gt.imu.yaw_rate_rps, gt.speed_mps, gt.lane.offset_m))
        k = np.array([r[0] for r in rows])
        if (k > 1e-3).sum() > 30 and (k < -1e-3).sum() > 30:
            break
    rows = np.array(rows)
    k = rows[:, 0]
    assert (k > 1e-3).sum() > 30 and (k < -1e-3).sum() > 30, "curvature did not take both signs"
    assert np.abs(rows[:, 3]).max() < 0.2  # the autopilot keeps its lane
    # on an arc in steady state the yaw rate is v * curvature
    steady = np.flatnonzero(np.abs(k) > 1e-3)[5:]
    err = rows[steady, 1] - rows[steady, 2] * k[steady]
    assert np.median(np.abs(err)) < 1e-3


def test_loop_is_a_closed_circuit_over_3_km_with_landmarks_off_the_road(autopilot_world):
    w = autopilot_world("loop")
    net = w.env.road.network
    nodes = _chain(net)
    assert nodes[0] == "0" and "0" in net.graph[nodes[-1]]
    for lane_id in (0, 1):
        lanes = segments(net, lane_id)
        assert np.allclose(lanes[-1].position(lanes[-1].length, 0), lanes[0].position(0, 0), atol=1e-6)
        for a, b in zip(lanes, lanes[1:]):
            assert np.allclose(a.position(a.length, 0), b.position(0, 0), atol=1e-6)
    length = sum(lane.length for lane in segments(net, 0))
    assert length >= 3000.0
    signs = [o for o in w.env.road.objects if isinstance(o, Sign)]
    landmarks = w.landmark_map()
    assert len(landmarks) == len(signs) >= int(length // 100)
    assert sorted(landmarks.ids) == sorted(s.marker_id for s in signs)
    all_lanes = [lane for tos in net.graph.values() for lanes in tos.values() for lane in lanes]
    for mid, (x, y, z) in zip(landmarks.ids, landmarks.positions_m):
        p = world_to_hw_xy(np.array([x, y]))
        assert z > 1.0
        for lane in all_lanes:
            s, lat = lane.local_coordinates(p)
            if -1.0 <= s <= lane.length + 1.0:  # beside this segment: off the paved surface
                assert abs(lat) > lane.width / 2 + SHOULDER_M, (mid, lat)


def test_indexed_network_answers_like_highway_env():
    from highway_env.road.road import RoadNetwork

    net = winding_road(np.random.default_rng(3), lanes=3, length_m=2600.0)
    lanes = [lane for tos in net.graph.values() for ls in tos.values() for lane in ls]
    rng = np.random.default_rng(0)
    for _ in range(400):
        lane = lanes[rng.integers(len(lanes))]
        p = lane.position(rng.uniform(-5, lane.length + 5), rng.uniform(-6, 6))
        if rng.random() < 0.1:
            p = p + rng.normal(0, 100, 2)  # off the road: the full search answers
        h = lane.heading_at(0.0) + rng.normal(0, 0.3)
        assert net.get_closest_lane_index(p, h) == RoadNetwork.get_closest_lane_index(net, p, h)


@pytest.mark.slow
def test_a_snapshot_builds_each_sign_once_and_every_vehicle_each_frame():
    from percept.sims.snapshot import object_state, scene_from_road

    world = SimWorld(WorldConfig("loop", seed=0, autopilot=True))
    first = {s.obj_id: s for s in scene_from_road(world.env.road, world.ego, world.ids).objects}
    world.step()
    later = {s.obj_id: s for s in scene_from_road(world.env.road, world.ego, world.ids).objects}
    signs = {world.ids(o) for o in world.env.road.objects if isinstance(o, Sign)}
    assert signs and all(later[i] is first[i] for i in signs)
    # the kept states are what a fresh snapshot of the sign gives
    assert all(object_state(world.ids.objects[i], i) == later[i] for i in signs)
    assert all(later[i] is not first[i] for i in later if i not in signs)
