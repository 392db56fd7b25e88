"""Closed-loop checks of the scenarios' traffic with the autopilot ego (highway-env's IDM), ground truth only:
every scenario builds, the highway's lanes and traffic, the braking lead, the cut-in and the crossing people."""

import types

import numpy as np
import pytest

from percept.sims import SCENARIOS, WorldConfig
from percept.sims.road_geometry import SHOULDER_M
from percept.sims.scenarios.catalog import CROSSING_LANE_W

DT = 1 / 15


@pytest.mark.parametrize("name", list(SCENARIOS))
def test_every_scenario_builds_for_seeds_0_to_2(name, scenario_env):
    # the highway-env side only (a SimWorld adds the renderer, ~1 s); the tests below build a SimWorld of each
    starts = []
    for seed in range(3):
        e = scenario_env(name, seed)
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
def highway(autopilot_world):
    """The highway world's start state, then 30 steps of ground truth."""
    w = autopilot_world("highway")
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


def test_same_seed_gives_identical_ground_truth(autopilot_world):
    runs = []
    for _ in range(2):
        w = autopilot_world("cut-in", seed=1, fast=False)
        out = []
        for _ in range(10):
            w.step()
            out.append(w.observe(render=False)[1].to_dict())
        runs.append(out)
    assert runs[0] == runs[1]
    assert runs[0][-1]["objects"]


@pytest.fixture(scope="module")
def lead_brake(autopilot_world):
    """Speeds [m/s] of the braking lead and of the ego, from the start to 6 s after the lead starts braking."""
    w = autopilot_world("lead-brake")
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


def test_cut_in_gap_and_final_lane(autopilot_world, scenario_env):
    for seed in range(3):  # the configured trigger gap, all seeds
        e = scenario_env("cut-in", seed)
        assert 12.0 <= e.scripted[0].cut_in_gap_m <= 20.0
        e.close()
    w = autopilot_world("cut-in")
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


def test_crossing_ego_speed_range(scenario_env):
    for seed in range(3):
        e = scenario_env("crossing", seed)
        assert 20.0 / 3.6 <= e.vehicle.speed <= 60.0 / 3.6
        assert e.cruise_speed_mps == e.vehicle.speed
        e.close()


@pytest.fixture(scope="module")
def crossing(autopilot_world):
    """Closed loop until the first crossing pedestrian has walked its whole way."""
    w = autopilot_world("crossing")
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
