"""The lane-changing traffic scenarios (dense, overtake, merge) with highway-env's own vehicles, ground truth only:
lane changes are opt-in (the other scenarios keep theirs off), each is deterministic for a seed, its traffic really
changes lanes, the ramp cars merge into the ego lane ahead of the ego, a car sits beside the ego, and the merge
road's gore has no guard rail across it."""

import numpy as np
import pytest
from highway_env.vehicle.behavior import AggressiveVehicle, DefensiveVehicle, IDMVehicle

from percept.sims import SCENARIOS, SimWorld, WorldConfig
from percept.sims.actors import LaneEnd, ScriptedVehicle
from percept.sims.env import PerceptEnv
from percept.sims.road_geometry import build_road_geometry
from percept.sims.scenarios import merge_road
from percept.sims.scenarios.placing import LANE_CHANGE_LATERAL_SPEED_MPS, PeoplePaced
from percept.sims.scenarios.traffic import MERGE_LEAD_IN_M, MERGE_RAMP_M
from percept.sims.snapshot import ObjectIds, scene_from_road

TRAFFIC = ["dense", "overtake", "merge"]
BLIND_BAND_M = (-7.7, 6.0)  # centre of a car in the next lane, relative to the ego's: seen by neither rig [m]


def _env(name: str, seed: int, autopilot: bool = True, mobil: bool = False) -> PerceptEnv:
    e = PerceptEnv(config={"scenario": SCENARIOS[name], "scenario_seed": seed, "autopilot": autopilot,
                           "autopilot_lane_changes": mobil})
    e.reset(seed=seed)
    return e


def _drive(e: PerceptEnv, steps: int, every=None) -> None:
    """Step the autopilot environment; ``every(k)`` after each step."""
    for k in range(steps):
        e.step(np.zeros(2, np.float32))
        if every is not None:
            every(k)


def _lane_changes(e: PerceptEnv, steps: int) -> int:
    """How many times a vehicle other than the ego moved to another lane of its road over ``steps`` steps."""
    lanes = {id(v): v.lane_index for v in e.road.vehicles}
    count = [0]

    def look(_):
        for v in e.road.vehicles[1:]:
            if v.lane_index[:2] == lanes[id(v)][:2] and v.lane_index[2] != lanes[id(v)][2]:
                count[0] += 1
            lanes[id(v)] = v.lane_index

    _drive(e, steps, look)
    return count[0]


@pytest.mark.parametrize("name", list(SCENARIOS))
def test_lane_changes_only_where_the_scenario_says(name):
    s = SCENARIOS[name]
    assert s.lane_changes == (name in TRAFFIC)
    e = _env(name, 0)
    others = e.road.vehicles[1:]
    changing = [v.enable_lane_change for v in others]
    if s.lane_changes:
        assert sum(changing) >= len(others) / 2, name
    else:
        assert not any(changing), name  # the existing scenarios keep their traffic as it was


def test_the_driven_ego_has_its_set_speed_as_target_speed_for_mobil():
    for name in TRAFFIC + ["highway"]:
        e = _env(name, 1, autopilot=False)
        assert e.vehicle.target_speed == e.cruise_speed_mps


def test_highway_envs_mobil_car_in_the_egos_place_wants_the_set_speed():
    # the anchor for progress wants what the percept car wants (dense: 30 m/s, above its 25 m/s start)
    wants = {}
    for name in TRAFFIC:
        e = _env(name, 1, mobil=True)
        assert e.vehicle.enable_lane_change and e.vehicle.target_speed == e.cruise_speed_mps
        wants[name] = e.vehicle.target_speed
    assert wants["dense"] == 30.0


def test_dense_is_highway_v0_like():
    e = _env("dense", 2)
    ego, others = e.vehicle, e.road.vehicles[1:]
    assert len(others) == 50 and len(e.road.network.graph["0"]["1"]) == 4
    # highway-env's own classes, paced like drivers when they change lanes
    assert {type(v).__mro__[2] for v in others} == {IDMVehicle, AggressiveVehicle, DefensiveVehicle}
    assert all(isinstance(v, PeoplePaced) for v in others)
    speeds = np.array([v.speed for v in others])
    assert np.all((speeds >= 20.0) & (speeds <= 30.0)) and e.cruise_speed_mps > np.median(speeds)
    dx = np.array([v.position[0] - ego.position[0] for v in others])
    assert (dx < -100).sum() >= 5 and (dx > 300).sum() >= 5  # around the ego, not only ahead of it


@pytest.mark.slow
@pytest.mark.parametrize("name, steps, least", [("dense", 300, 8), ("overtake", 300, 3)])
def test_traffic_really_changes_lanes(name, steps, least):
    for seed in (0, 1):
        assert _lane_changes(_env(name, seed), steps) >= least, (name, seed)


@pytest.mark.slow
@pytest.mark.parametrize("name", TRAFFIC)
def test_same_seed_same_traffic_other_seed_other_traffic(name):
    def states(seed):
        e = _env(name, seed)
        out = []
        _drive(e, 120, lambda k: out.append([(*np.round(v.position, 9), round(v.speed, 9), v.lane_index)
                                             for v in e.road.vehicles]))
        return out

    a, b = states(3), states(3)
    assert a == b
    assert states(4)[-1] != a[-1]


@pytest.mark.slow
def test_same_seed_gives_identical_ground_truth_in_a_world():
    runs = []
    for _ in range(2):
        w = SimWorld(WorldConfig("dense", 5, autopilot=True, scenery=False))
        out = []
        for _ in range(100):
            w.step()
            out.append(w.observe(render=False)[1].to_dict())
        runs.append(out)
    assert runs[0] == runs[1] and runs[0][-1]["objects"]


@pytest.mark.slow
def test_merge_ramp_cars_join_the_ego_lane_the_first_ahead_of_the_ego():
    for seed in range(3):
        e = _env("merge", seed)
        ego = e.vehicle
        ramp = [v for v in e.road.vehicles if isinstance(v, ScriptedVehicle)]
        joined: dict[int, float] = {}

        def look(_):
            for v in ramp:
                if id(v) not in joined and v.lane_index == ego.lane_index:
                    joined[id(v)] = float(v.position[0] - ego.position[0])

        _drive(e, 40 * 15, look)
        assert len(ramp) == 2 and id(ramp[0]) in joined, seed
        assert 20.0 <= joined[id(ramp[0])] <= 90.0, (seed, joined)
        assert not ego.crashed and not any(v.crashed for v in e.road.vehicles)


@pytest.mark.slow
def test_overtake_a_car_sits_beside_the_ego_unseen_for_seconds():
    for seed in range(3):
        e = _env("overtake", seed)
        ego = e.vehicle
        # a slow car 70-100 m ahead in the ego lane
        ahead = [v for v in e.road.vehicles[1:] if v.lane_index == ego.lane_index and v.position[0] > ego.position[0]]
        lead = min(ahead, key=lambda v: v.position[0])
        assert 70.0 <= lead.position[0] - ego.position[0] <= 100.0 and lead.speed < 22.0
        pacer = next(v for v in e.road.vehicles if isinstance(v, ScriptedVehicle))
        beside = []

        def look(_):
            dx = pacer.position[0] - ego.position[0]
            adjacent = abs(pacer.lane_index[2] - ego.lane_index[2]) == 1
            beside.append(adjacent and BLIND_BAND_M[0] + pacer.LENGTH / 2 <= dx <= BLIND_BAND_M[1] - pacer.LENGTH / 2)

        _drive(e, 30 * 15, look)
        run = max(len(r) for r in "".join("1" if b else "0" for b in beside).split("0"))
        assert run / 15 >= 5.0, (seed, run / 15)


def test_merge_lane_end_is_neither_drawn_nor_in_the_truth():
    e = _env("merge", 0)
    ends = [o for o in e.road.objects if isinstance(o, LaneEnd)]
    assert len(ends) == 1
    ids = ObjectIds()
    scene = scene_from_road(e.road, e.vehicle, ids)
    assert all(ids.objects[s.obj_id] is not ends[0] for s in scene.objects)


def test_merge_road_has_no_rail_between_the_road_and_its_ramp():
    net = merge_road(MERGE_LEAD_IN_M, MERGE_RAMP_M, 500.0)
    g = build_road_geometry(net)
    x_ramp, x_join = MERGE_LEAD_IN_M - MERGE_RAMP_M, MERGE_LEAD_IN_M + 80.0
    # world frame, y to the left: the main road's paved right edge is at y = -7.8 m, the ramp's left one at -10.7 m
    between = [p for edge, _ in g.edges for p in edge if x_ramp + 1 < p[0] < x_join and -10.65 < p[1] < -7.85]
    assert between == []
    right_rails = [edge for edge, out in g.edges if out == -1 and np.all(edge[:, 1] > -8.0)]
    assert right_rails and min(e[:, 0].max() for e in right_rails) <= x_ramp + 1  # it stops where the ramp starts
    outer = [edge for edge, out in g.edges if out == -1 and np.all(edge[:, 1] < -12.0)]
    assert outer  # the ramp's own outer edge keeps its rail


def test_straight_road_edges_are_whole():
    from percept.sims.scenarios import straight_road
    g = build_road_geometry(straight_road(3, 400.0))
    assert len(g.edges) == 2 and all(len(edge) == 401 for edge, _ in g.edges)


def test_merge_road_rejects_a_ramp_longer_than_its_lead_in():
    with pytest.raises(ValueError, match="the ramp must be 0 to 300 m long"):
        merge_road(300.0, 400.0, 100.0)


@pytest.mark.slow
@pytest.mark.parametrize("name", TRAFFIC)
def test_renders_at_night_and_in_rain(name):
    for cond in ("night", "rain"):
        w = SimWorld(WorldConfig(name, 0, condition=cond, autopilot=True))
        for _ in range(3):
            w.step()
        frame, gt = w.observe()
        assert frame.left.shape == frame.right.shape and frame.left.mean() > 5
        assert any(o.kind == "vehicle" for o in gt.objects)


@pytest.mark.slow
def test_lane_changing_cars_move_over_at_a_drivers_pace():
    # highway-env's own steering crosses the boundary about 1.3 s (Linear vehicles: under 1 s) after a car begins to
    # move over; paced like a driver it crosses about 2.3 s after
    e = _env("dense", 0)
    dt = 1 / e.config["policy_frequency"]
    began, leads, peak = {}, [], 0.0
    lanes = {id(v): v.lane_index for v in e.road.vehicles}

    def look(k):
        nonlocal peak
        for v in e.road.vehicles[1:]:
            # the road is straight along x: lateral speed = v sin(heading)
            lateral = abs(v.speed * np.sin(v.heading))
            if lateral > 0.1:
                began.setdefault(id(v), k)
                peak = max(peak, lateral)
            else:
                began.pop(id(v), None)
            if v.lane_index[2] != lanes[id(v)][2] and id(v) in began:
                leads.append((k - began[id(v)]) * dt)
            lanes[id(v)] = v.lane_index

    _drive(e, 300, look)
    assert len(leads) >= 5
    assert peak <= LANE_CHANGE_LATERAL_SPEED_MPS * 1.15  # the heading lags the command and overshoots a little
    assert np.median(leads) >= 2.0, leads  # a car moving over from off its lane's centre crosses sooner
