"""Closed-loop checks of the six scenarios with the autopilot ego (highway-env's IDM), ground truth only."""

import types

import numpy as np
import pytest
from highway_env.road.lane import CircularLane

from percept.sims import SCENARIOS, SimWorld, WorldConfig
from percept.sims.actors import Sign
from percept.sims.coords import world_to_hw_xy
from percept.sims.env import PerceptEnv
from percept.sims.ground_truth import lane_truth
from percept.sims.road_geometry import SHOULDER_M
from percept.sims.scenarios import ClothoidLane, winding_road
from percept.sims.scenarios.catalog import CROSSING_LANE_W, _chain

DT = 1 / 15


def world(name: str, seed: int = 0, fast: bool = True) -> SimWorld:
    w = SimWorld(WorldConfig(name, seed, autopilot=True, scenery=False))
    if fast:
        # SimWorld discards highway-env's own Kinematics observation, which costs about 2/3 of a step (pandas);
        # it draws no random numbers, so skipping it changes nothing else
        w.env.observation_type.observe = lambda: None
    return w


def env(name: str, seed: int) -> PerceptEnv:
    e = PerceptEnv(config={"scenario": SCENARIOS[name], "scenario_seed": seed, "autopilot": True})
    e.reset(seed=seed)
    return e


def segments(net, lane_id: int):
    nodes = _chain(net)
    return [net.graph[a][b][lane_id] for a, b in zip(nodes, nodes[1:] + ["0"]) if b in net.graph.get(a, {})]


@pytest.mark.parametrize("name", list(SCENARIOS))
def test_every_scenario_builds_for_seeds_0_to_2(name):
    # the highway-env side only (a SimWorld adds the renderer, ~1 s); the tests below build a SimWorld of each
    starts = []
    for seed in range(3):
        e = env(name, seed)
        ego = e.vehicle
        assert ego is e.road.vehicles[0] and not ego.crashed
        _, lat = ego.lane.local_coordinates(ego.position)
        assert abs(lat) < 1e-6 and ego.speed > 0
        vehicles = e.road.vehicles
        for i, a in enumerate(vehicles):  # nobody starts overlapping another vehicle in its lane
            for b in vehicles[i + 1:]:
                if a.lane_index == b.lane_index:
                    assert np.linalg.norm(a.position - b.position) > a.LENGTH, (name, seed)
        starts.append([(tuple(np.round(v.position, 6)), round(v.speed, 6)) for v in vehicles])
        e.close()
    assert starts[0] != starts[1]  # the seed matters


@pytest.mark.parametrize("kwargs, match", [
    ({"scenario": "motorway"}, "unknown scenario 'motorway'"),
    ({"condition": "fog"}, "unknown condition 'fog'"),
    ({"seed": -1}, "seed must be >= 0"),
])
def test_bad_config_raises_value_error(kwargs, match):
    with pytest.raises(ValueError, match=match):
        WorldConfig(**kwargs)


@pytest.fixture(scope="module")
def highway():
    """The highway world's start state, then 30 steps of ground truth."""
    w = world("highway")
    ego = w.env.vehicle
    r = types.SimpleNamespace(world=w, lanes=len(w.env.road.network.graph["0"]["1"]), ego_x=ego.position[0],
                              others=[(v.lane_index, v.position[0], v.speed) for v in w.env.road.vehicles[1:]],
                              ego_lane=ego.lane_index, gt0=w.observe(render=False)[1], steps=[])
    for _ in range(30):
        w.step()
        r.steps.append((w.observe(render=False)[1], w.ego.position.copy()))
    return r


def test_highway_four_lanes_lead_ahead_traffic_speeds(highway):
    r = highway
    assert r.lanes == 4
    speeds = np.array([v for _, _, v in r.others])
    assert np.all((speeds >= 25.0) & (speeds <= 30.0)), speeds
    lead_x = min(x for lane, x, _ in r.others if lane == r.ego_lane and x > r.ego_x)
    assert 40.0 <= lead_x - r.ego_x <= 60.0
    in_path = [o for o in r.gt0.objects if o.kind == "vehicle" and o.position_m[0] > 0 and abs(o.position_m[1]) < 1]
    assert min(o.position_m[0] for o in in_path) == pytest.approx(lead_x - r.ego_x, abs=1e-6)


def test_ground_truth_lane_on_a_straight_is_centred_and_aligned(highway):
    for gt, pos_hw in highway.steps:
        assert abs(gt.lane.offset_m) < 0.05 and abs(gt.lane.heading_rad) < 0.01
        assert gt.lane.curvature_1pm == 0.0 and gt.lane.width_m == 4.0
        assert (gt.ego.x_m, gt.ego.y_m) == pytest.approx((pos_hw[0], -pos_hw[1]))
        assert gt.imu.is_finite() and not gt.crashed
    assert highway.steps[-1][0].time_s == pytest.approx(30 * DT)


def test_same_seed_gives_identical_ground_truth():
    runs = []
    for _ in range(2):
        w = world("cut-in", seed=1, fast=False)
        out = []
        for _ in range(10):
            w.step()
            out.append(w.observe(render=False)[1].to_dict())
        runs.append(out)
    assert runs[0] == runs[1]
    assert runs[0][-1]["objects"]


@pytest.fixture(scope="module")
def lead_brake():
    """Speeds [m/s] of the braking lead and of the ego, from the start to 6 s after the lead starts braking."""
    w = world("lead-brake")
    lead = w.env.scripted[0]
    lead_v, ego_v = [lead.speed], [w.ego.speed]
    for _ in range(int((lead.brake_at_s + 6.0) / DT)):
        w.step()
        lead_v.append(lead.speed)
        ego_v.append(w.ego.speed)
    return types.SimpleNamespace(world=w, lead=lead, lead_v=np.array(lead_v), ego_v=np.array(ego_v))


def test_lead_brake_decelerates_at_6_from_25_mps(lead_brake):
    speed, lead = lead_brake.lead_v, lead_brake.lead
    accel = np.diff(speed) / DT
    k0 = np.flatnonzero(accel < -1.0)[0]
    assert k0 * DT == pytest.approx(lead.brake_at_s, abs=2 * DT)
    assert speed[k0] == pytest.approx(25.0, abs=1.0)
    until_stop = accel[k0:k0 + int(speed[k0] / 6.0 / DT)]
    np.testing.assert_allclose(until_stop, -6.0, atol=0.3)
    assert abs(speed[-1]) < 0.5
    assert not lead_brake.world.ego.crashed


def test_lead_brake_stays_stopped_and_never_reverses(lead_brake):
    assert lead_brake.lead_v.min() >= 0.0
    assert np.all(lead_brake.lead_v[-15:] == 0.0)


def test_cut_in_gap_and_final_lane():
    for seed in range(3):  # the configured trigger gap, all seeds
        e = env("cut-in", seed)
        assert 12.0 <= e.scripted[0].cut_in_gap_m <= 20.0
        e.close()
    w = world("cut-in")
    cutter, ego = w.env.scripted[0], w.ego
    ego_lane = w.env.road.network.get_lane(ego.lane_index)
    lat0 = ego_lane.local_coordinates(cutter.position)[1]
    assert abs(lat0) == pytest.approx(4.0)
    start_gap = None
    for k in range(300):
        gap = cutter.position[0] - ego.position[0] - cutter.LENGTH
        w.step()
        if start_gap is None and abs(ego_lane.local_coordinates(cutter.position)[1] - lat0) > 0.02:
            start_gap = gap  # the bumper gap when it started moving across
            end = k + 45
        if start_gap is not None and k >= end:
            break
    assert start_gap is not None, "the vehicle never changed lane"
    assert 10.0 <= start_gap <= 22.0
    assert start_gap == pytest.approx(cutter.cut_in_gap_m, abs=0.5)
    assert cutter.lane_index == ego.lane_index
    assert abs(ego_lane.local_coordinates(cutter.position)[1]) < 0.3
    _, gt = w.observe(render=False)
    ahead = [o for o in gt.objects if o.obj_id == w.ids(cutter)][0]
    assert ahead.position_m[0] > 0 and abs(ahead.position_m[1]) < 0.5
    assert not gt.crashed


def test_crossing_ego_speed_range():
    for seed in range(3):
        e = env("crossing", seed)
        assert 20.0 / 3.6 <= e.vehicle.speed <= 60.0 / 3.6
        assert e.cruise_speed_mps == e.vehicle.speed
        e.close()


@pytest.fixture(scope="module")
def crossing():
    """Closed loop until the first crossing pedestrian has walked its whole way."""
    w = world("crossing")
    peds = w.env.pedestrians
    r = types.SimpleNamespace(world=w, crossing=[p for p in peds if p.crossing],
                              roadside=[p for p in peds if not p.crossing])
    r.first = r.crossing[0]
    r.lane = w.env.road.network.get_lane(w.ego.lane_index)
    track, roadside_lat, ego_v = [r.first.position.copy()], [], []
    for _ in range(900):
        w.step()
        track.append(r.first.position.copy())
        roadside_lat.append([r.lane.local_coordinates(p.position)[1] for p in r.roadside])
        ego_v.append(w.ego.speed)
        if r.first.walked_m >= r.first.walk_distance_m:
            break
    r.track, r.roadside_lat, r.ego_v = np.array(track), np.array(roadside_lat), np.array(ego_v)
    return r


def test_crossing_pedestrians_cross_and_roadside_ones_stay_off_the_road(crossing):
    r, w = crossing, crossing.world
    assert len(r.crossing) == 3 and len(r.roadside) == 4
    assert r.first.walked_m == pytest.approx(r.first.walk_distance_m), "the first crossing pedestrian never finished"
    step = np.linalg.norm(np.diff(r.track, axis=0), axis=1) / DT
    walking = step[step > 0]
    np.testing.assert_allclose(walking[:-1], 1.39, atol=1e-9)  # the last step ends the walk early
    assert walking[-1] <= 1.39 + 1e-9
    assert np.ptp(r.track[:, 0]) < 1e-9  # straight across the road
    lat = r.lane.local_coordinates(w.ego.position)[1] + np.array([-1, 1]) * r.lane.width / 2
    assert r.track[:, 1].min() < lat[0] and r.track[:, 1].max() > lat[1]  # all the way across the ego lane
    # the paved surface: both lanes plus the shoulders (highway-env lateral, + right, from the ego lane centre)
    paved = (-1.5 * CROSSING_LANE_W - SHOULDER_M, CROSSING_LANE_W / 2 + SHOULDER_M)
    assert np.all((r.roadside_lat < paved[0]) | (r.roadside_lat > paved[1]))
    assert not w.ego.crashed and not r.first.hit
    _, gt = w.observe(render=False)
    flags = {o.obj_id: o.crossing for o in gt.objects if o.kind == "pedestrian"}
    assert flags[w.ids(r.first)] is True
    assert all(flags[w.ids(p)] is False for p in r.roadside if w.ids(p) in flags)


def test_crossing_autopilot_ego_never_reverses(crossing):
    assert crossing.ego_v.min() >= 0.0


def test_curves_radii_and_curvature_sign_of_every_arc():
    for seed in range(3):
        e = env("curves", seed)
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
            probe = types.SimpleNamespace(lane=lane, position=lane.position(s, 0.0), heading=lane.heading_at(s),
                                          lane_index=("?", "?", 1))
            k = lane_truth(probe).curvature_1pm
            if isinstance(lane, CircularLane):
                expect = (-1.0 if lane.clockwise else 1.0) / lane.radius
            elif isinstance(lane, ClothoidLane):
                expect = -lane.curvature_at(s)
            else:
                expect = 0.0
            assert k == pytest.approx(expect, rel=1e-3, abs=1e-9)
        e.close()


def test_curves_curvature_is_continuous_through_clothoid_transitions():
    """No curvature steps: along the ego lane, the truth changes by at most the steepest spiral's rate x 1 m."""
    e = env("curves", 0)
    lanes = segments(e.road.network, 1)
    assert any(isinstance(lane, ClothoidLane) for lane in lanes)
    ks = []
    for lane in lanes:
        for s in np.arange(0.0, lane.length, 1.0):
            probe = types.SimpleNamespace(lane=lane, position=lane.position(s, 0.0), heading=lane.heading_at(s),
                                          lane_index=("?", "?", 1))
            ks.append(lane_truth(probe).curvature_1pm)
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
    assert lane.heading_at(lane.length) == pytest.approx(0.3 + 60.0 / 300.0, abs=1e-12)
    # the offset lane inside the turn is shorter: ds = (1 - offset k) du
    assert lane.length == pytest.approx(60.0 - 8.0 * 60.0 / 300.0, abs=1e-9)
    with pytest.raises(ValueError, match="positive length"):
        ClothoidLane(np.zeros(2), 0.0, 0.0, 0.0, 0.01)


def test_curves_closed_loop_curvature_takes_both_signs_and_matches_yaw_rate():
    w = world("curves")
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


def test_loop_is_a_closed_circuit_over_3_km_with_landmarks_off_the_road():
    w = world("loop")
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
