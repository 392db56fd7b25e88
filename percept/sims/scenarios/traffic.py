"""Scenarios with lane-changing traffic: highway-env's IDMVehicle with MOBIL lane changes (and its
AggressiveVehicle and DefensiveVehicle), as in its highway-v0 and merge-v0, around the ego.

MOBIL (Kesting, Treiber, Helbing 2007) lets a car move over when it gains acceleration there and the new follower
need not brake harder than 2 m/s²; the ego's target speed is its set speed (env._reset), so traffic judges a gap
ahead of the ego as it would any other. Every draw comes from the scenario's generator ``rng`` or highway-env's
``env.np_random`` (seeded with the scenario seed), so a seed gives the same traffic.
"""

from __future__ import annotations

import numpy as np
from highway_env.road.road import Road
from highway_env.vehicle.behavior import AggressiveVehicle, DefensiveVehicle, IDMVehicle, LinearVehicle

from ..actors import LaneEnd, ScriptedVehicle
from .placing import new_road, place_idm, place_traffic
from .roads import merge_road, straight_road

HIGHWAY_V0_SPACING = np.exp(-5 / 40 * 4)
"""highway-env's Vehicle.create_random on 4 lanes: the gap to the previous car is (12 + v) exp(-5 lanes / 40) / density
metres, in any lane, times a uniform factor in [0.9, 1.1]."""
AGGRESSIVE_SHARE, DEFENSIVE_SHARE = 0.15, 0.15
"""Shares of highway-env's AggressiveVehicle and DefensiveVehicle in ``dense``; the rest are IDMVehicles."""


def _mixed_class(rng) -> type:
    """IDMVehicle, AggressiveVehicle or DefensiveVehicle in the shares above."""
    u = float(rng.random())
    if u < AGGRESSIVE_SHARE:
        return AggressiveVehicle
    return DefensiveVehicle if u < AGGRESSIVE_SHARE + DEFENSIVE_SHARE else IDMVehicle


def highway_v0_traffic(road, rng, lanes: int, s0: float, count: int, speeds: tuple[float, float],
                       keep_clear: tuple[int, float, float], density: float = 1.0) -> None:
    """``count`` vehicles from s0 [m] on, one after another as highway-v0 places them (each HIGHWAY_V0_SPACING
    (12 + v) / density ahead of the previous, in a random lane), a mix of highway-env's classes with MOBIL lane
    changes; speeds: (low, high) [m/s]; keep_clear: (lane, from, to) [m] left empty (the ego's place)."""
    s = s0
    while count > 0:
        speed = float(rng.uniform(*speeds))
        # s_k = s_(k-1) + exp(-5 lanes / 40) (12 + v) / density U(0.9, 1.1)
        s += HIGHWAY_V0_SPACING * (12.0 + speed) / density * float(rng.uniform(0.9, 1.1))
        lane = int(rng.integers(lanes))
        if lane == keep_clear[0] and keep_clear[1] <= s <= keep_clear[2]:
            continue
        v = place_idm(road, ("0", "1", lane), s, speed, cls=_mixed_class(rng), lane_change=True)
        # highway-v0 draws each IDM's acceleration exponent (the Linear ones keep theirs)
        if not isinstance(v, LinearVehicle):
            v.randomize_behavior()
        count -= 1


def build_dense(env, rng) -> Road:
    """highway-v0's traffic around the ego: 4 lanes, 50 vehicles at 20-30 m/s from 250 m behind the ego."""
    road = new_road(env, straight_road(4, 4000.0))
    env.road = road
    ego_lane, ego_s = int(rng.integers(4)), 400.0
    env.make_ego(("0", "1", ego_lane), ego_s, 25.0)
    env.cruise_speed_mps = 30.0  # above most of the traffic: the ego ends up following someone
    highway_v0_traffic(road, rng, 4, ego_s - 250.0, 50, (20.0, 30.0), (ego_lane, ego_s - 30.0, ego_s + 50.0))
    return road


def build_overtake(env, rng) -> Road:
    """3 lanes: a slow car ahead in the ego lane; on the left two faster cars closing from behind, within the rear
    rig's reach, and traffic from 150 m ahead on; on the right a car that comes up from behind and stays beside the
    ego, where neither rig sees it, for 6-10 s. Once the two have passed, the left lane is open for an overtake; the
    ego lane's own followers start 200 m back or more."""
    road = new_road(env, straight_road(3, 3000.0))
    env.road = road
    ego_s = 300.0
    env.make_ego(("0", "1", 1), ego_s, 25.0)
    env.cruise_speed_mps = 27.0
    place_idm(road, ("0", "1", 1), ego_s + float(rng.uniform(70.0, 100.0)), float(rng.uniform(18.0, 21.0)))
    # the one beside: centre 0-2 m behind the ego's (the blind band is ~7.7 m behind to 6 m ahead)
    place_idm(road, ("0", "1", 2), ego_s - float(rng.uniform(40.0, 60.0)), 30.0, cls=ScriptedVehicle,
              pace_offset_m=-float(rng.uniform(0.0, 2.0)), pace_s=float(rng.uniform(6.0, 10.0)))
    place_traffic(road, rng, [0], ego_s - 85.0, ego_s - 35.0, 2, (29.0, 33.0), [], lane_change=True)
    place_traffic(road, rng, [0], ego_s + 150.0, ego_s + 700.0, 4, (27.0, 31.0), [], lane_change=True)
    place_traffic(road, rng, [2], ego_s + 40.0, ego_s + 600.0, 4, (22.0, 26.0), [], lane_change=True)
    place_traffic(road, rng, [1], ego_s - 350.0, ego_s - 200.0, 2, (25.0, 28.0), [], lane_change=True)
    return road


MERGE_LEAD_IN_M, MERGE_RAMP_M, MERGE_LANE_M = 700.0, 600.0, 300.0
"""The merge road: lead-in before the ramp converges, how long the ramp runs beside it, and the acceleration lane
(highway-env's is 80 m: its cars brake for the lane's end from before they may merge, and miss gaps at 25 m/s) [m]."""


RAMP_B_SAFE_MPS2 = 4.0
"""MOBIL's safe braking b_safe for the ramp cars: the new follower may have to brake this hard [m/s²]. Kesting,
Treiber and Helbing's default (2007); highway-env's cars use 2 m/s², with which a car merging at the ego's speed
needs a ~60 m gap."""


def build_merge(env, rng) -> Road:
    """highway-env's merge layout: 2 lanes and a ramp; two ramp cars merge into the ego lane, the first 35-50 m
    ahead of the ego (centre to centre, as it reaches the acceleration lane), the second further back; MOBIL traffic
    on the road. The first ramp car leads the ramp, so nothing slows it before it merges."""
    net = merge_road(MERGE_LEAD_IN_M, MERGE_RAMP_M, 1500.0, merge_m=MERGE_LANE_M)
    road = new_road(env, net, connected=True)
    env.road = road
    speed = 25.0
    x_join = MERGE_LEAD_IN_M + 80.0  # where the acceleration lane begins
    t_join = float(rng.uniform(14.0, 20.0))  # when the first ramp car gets there [s]
    first = float(rng.uniform(35.0, 50.0))
    ego_s = x_join - first - speed * t_join
    env.make_ego(("0", "1", 1), ego_s, speed)
    # the first ramp car comes faster than the ego and reaches x_join when the ego, at its speed, is ``first``
    # metres behind; the second follows it up the ramp, slower
    v = float(rng.uniform(28.0, 30.0))
    s_first = x_join - v * t_join - (MERGE_LEAD_IN_M - MERGE_RAMP_M)
    for s, speed_r in ((s_first, v), (s_first - float(rng.uniform(60.0, 80.0)), float(rng.uniform(26.5, 27.5)))):
        car = place_idm(road, ("0", "1", 2), s, speed_r, cls=ScriptedVehicle, paced=True, merge_road=("2", "3"))
        car.LANE_CHANGE_MAX_BRAKING_IMPOSED = RAMP_B_SAFE_MPS2
    road.objects.append(LaneEnd(road, net.get_lane(("2", "3", 2)).position(MERGE_LANE_M, 0.0)))
    place_traffic(road, rng, [0], ego_s - 150.0, ego_s + 500.0, 6, (24.0, 29.0), [], lane_change=True)
    place_traffic(road, rng, [1], ego_s + 220.0, ego_s + 500.0, 2, (25.0, 28.0), [], lane_change=True)
    place_traffic(road, rng, [1], ego_s - 150.0, ego_s - 40.0, 2, (24.0, 27.0), [], lane_change=True)
    return road
