"""QuickRoad gives highway-env's Road's answers: the same traffic, lane changes, merges and crashes, step for step."""

import numpy as np
import pytest
from highway_env.road.road import Road

import percept.sims.scenarios.placing as placing
from percept.sims import SCENARIOS
from percept.sims.env import PerceptEnv
from percept.sims.scenarios.quick_road import QuickRoad


def _states(monkeypatch, road_cls, name: str, seed: int, steps: int, accel: float) -> list:
    """Every vehicle's and object's state after each step, the ego driven at a fixed normalised action."""
    monkeypatch.setattr(placing, "QuickRoad", road_cls)
    e = PerceptEnv(config={"scenario": SCENARIOS[name], "scenario_seed": seed, "autopilot": False})
    e.reset(seed=seed)
    assert type(e.road) is road_cls
    out = []
    for _ in range(steps):
        e.step(np.array([accel, 0.0], np.float32))
        out.append([(v.position.tobytes(), float(v.speed), v.lane_index, getattr(v, "target_lane_index", None), v.crashed)
                    for v in e.road.vehicles] + [(o.position.tobytes(), o.crashed, o.hit) for o in e.road.objects])
    return out


@pytest.mark.slow
@pytest.mark.parametrize("name, accel", [("dense", 0.3), ("dense", 1.0), ("merge", 0.3), ("crossing", 1.0)])
def test_quick_road_matches_highway_env_road(monkeypatch, name, accel):
    # accel 1.0 (the most the ego can) drives it into the traffic ahead: crashes must match too
    quick = _states(monkeypatch, QuickRoad, name, 0, 300, accel)
    plain = _states(monkeypatch, Road, name, 0, 300, accel)
    assert quick == plain
    if name == "dense" and accel == 1.0:
        assert any(crashed for *_, crashed in quick[-1][:51])


def test_outside_a_step_the_neighbour_search_is_highway_envs():
    e = PerceptEnv(config={"scenario": SCENARIOS["dense"], "scenario_seed": 0, "autopilot": True})
    e.reset(seed=0)
    assert isinstance(e.road, QuickRoad)
    for v in e.road.vehicles[:10]:
        assert e.road.neighbour_vehicles(v) == Road.neighbour_vehicles(e.road, v)
