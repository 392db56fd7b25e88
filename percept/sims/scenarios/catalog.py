"""The scenarios: road, traffic, pedestrians and signs, each deterministic for a seed.

Every builder works in highway-env's plane (y to the right) with highway-env's own classes and
returns the Road; the ego is made by ``env.make_ego``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
from highway_env.road.road import Road

from ..actors import Pedestrian, ScriptedVehicle, Sign
from .placing import chain_nodes, lane_at, new_road, place_idm, place_traffic
from .roads import loop_road, straight_road, winding_road
from .traffic import build_dense, build_merge, build_overtake


@dataclass(frozen=True)
class Scenario:
    """One scenario of the catalogue: its name, what it is and how its road is built.

    lane_changes: its traffic changes lanes (highway-env's MOBIL), so vehicles move into and out of the ego lane
    and come up beside and behind the ego; what watches the neighbouring lanes (the rear rig) is on by default
    there. Elsewhere every vehicle keeps its lane, apart from a scripted cut-in.
    """

    name: str  # its name on the command line
    summary: str  # what it is, one line
    duration_s: float  # default run length [s]
    build: Callable  # build(env, rng) -> highway-env Road, with the ego made by ``env.make_ego``
    ego_speed_mps: float = 25.0  # the ego's nominal speed [m/s] (``build`` sets its start and cruise speeds)
    lane_changes: bool = False  # True: the traffic changes lanes on its own (MOBIL); False: it keeps its lanes
    watch_beside: bool = False  # the rear rig is on by default even though the traffic keeps its lanes: the ego
    # needs to know whether the lanes beside it are free (an evasive manoeuvre)

    @property
    def rear_by_default(self) -> bool:
        """Whether the rear rig is on unless asked otherwise."""
        return self.lane_changes or self.watch_beside


def build_highway(env, rng) -> Road:
    road = new_road(env, straight_road(4, 3000.0))
    env.road = road
    ego_lane = int(rng.integers(1, 3))
    env.make_ego(("0", "1", ego_lane), 60.0, 25.0)
    env.cruise_speed_mps = 30.0  # faster than the lead, so the ego settles into following it
    lead_s = 60.0 + float(rng.uniform(40.0, 60.0))
    place_idm(road, ("0", "1", ego_lane), lead_s, float(rng.uniform(25.0, 27.0)))
    place_traffic(road, rng, [0, 1, 2, 3], 0.0, 700.0, 14, (25.0, 30.0), [(ego_lane, 30.0, lead_s + 40.0)])
    return road


def build_curves(env, rng) -> Road:
    road = new_road(env, winding_road(rng, lanes=3, length_m=2600.0))
    env.road = road
    env.make_ego(("0", "1", 1), 40.0, 20.0)
    idx, s = lane_at(road.network, 1, 95.0)
    place_idm(road, idx, s, 20.0)
    place_traffic(road, rng, [0, 1, 2], 0.0, 800.0, 10, (18.0, 22.0), [(1, 10.0, 140.0)])
    return road


def build_lead_brake(env, rng) -> Road:
    road = new_road(env, straight_road(3, 2000.0))
    env.road = road
    env.make_ego(("0", "1", 1), 60.0, 25.0)
    # the ego (set to 25 m/s) follows a lead at 24 m/s, from bumper gaps of 40-50 m, until the lead brakes
    place_idm(road, ("0", "1", 1), 60.0 + float(rng.uniform(45.0, 55.0)), 24.0, cls=ScriptedVehicle,
         brake_at_s=float(rng.uniform(8.0, 10.0)), brake_mps2=-6.0)
    place_traffic(road, rng, [0, 2], 0.0, 500.0, 8, (24.0, 28.0), [])
    return road


def build_cut_in(env, rng) -> Road:
    road = new_road(env, straight_road(3, 2000.0))
    env.road = road
    env.make_ego(("0", "1", 1), 60.0, 25.0)
    side = int(rng.choice([0, 2]))
    place_idm(road, ("0", "1", side), 60.0 + float(rng.uniform(35.0, 50.0)), 21.0, cls=ScriptedVehicle,
         cut_in_lane=("0", "1", 1), cut_in_gap_m=float(rng.uniform(12.0, 20.0)))
    place_idm(road, ("0", "1", 1), 60.0 + 150.0, 24.0)
    place_traffic(road, rng, [2 - side], 0.0, 500.0, 5, (24.0, 28.0), [])
    return road


CLOSE_CUT_IN_SPEED_MPS = 11.0
"""The speed of ``cut-in-close``'s slow car [m/s]: 14 m/s slower than the ego, a car pulling out at a truck's pace."""
CLOSE_CUT_IN_AT_S = 11.0
"""When, into the run, the slow car pulls out [s]: after the car beside of the variant has come up from behind."""
CLOSE_CUT_IN_LATERAL_MPS = 2.0
"""The cap on its lateral speed as it pulls out [m/s]: twice a lane-changing driver's (``placing.PeoplePaced``)."""


def build_cut_in_close(env, rng) -> Road:
    """A slow car in the next lane pulls out in front of the ego when its bumper gap is 10-12 m, 14 m/s slower:
    braking alone at 8 m/s² cannot cancel the closing (12 m) before it is in the ego's way, and the lane on the
    other side is free. On odd seeds, the variant: a car rides beside the ego in that other lane, and the slow car
    is 8-9 m/s slower and pulls out 12-15 m ahead, so that full braking avoids it (the car beside comes up from behind
    in the first seconds, where the rear rig sees it)."""
    road = new_road(env, straight_road(3, 2000.0))
    env.road = road
    ego_s = 60.0
    env.make_ego(("0", "1", 1), ego_s, 25.0)
    side = int(rng.choice([0, 2]))
    boxed = env.config["scenario_seed"] % 2 == 1
    speed = 25.0 - float(rng.uniform(8.0, 9.0)) if boxed else CLOSE_CUT_IN_SPEED_MPS
    gap = float(rng.uniform(12.0, 15.0) if boxed else rng.uniform(12.0, 14.0))
    # it pulls out about CLOSE_CUT_IN_AT_S into the run: x = x_ego + L + gap + (v_ego - v) t (its centre, IDM's
    # own length)
    start = ego_s + 5.0 + gap + (25.0 - speed) * CLOSE_CUT_IN_AT_S
    cutter = place_idm(road, ("0", "1", side), start, speed, cls=ScriptedVehicle, paced=True,
                       cut_in_lane=("0", "1", 1), cut_in_gap_m=gap)
    cutter.lateral_speed_mps = CLOSE_CUT_IN_LATERAL_MPS
    if boxed:
        # in the other lane: comes up from behind (seen by the rear rig) and stays beside the ego for the rest of the
        # run, its centre 0-2 m behind the ego's
        place_idm(road, ("0", "1", 2 - side), ego_s - 40.0, 30.0, cls=ScriptedVehicle,
                  pace_offset_m=-float(rng.uniform(0.0, 2.0)), pace_s=60.0)
    place_traffic(road, rng, [0, 1, 2], ego_s - 400.0, ego_s - 150.0, 4, (24.0, 27.0), [])
    return road


CROSSING_LANE_W = 3.5


def build_crossing(env, rng) -> Road:
    """Two-lane road; people cross the ego lane at ~5 km/h (Euro NCAP CPNA-like), others stay on the verge."""
    road = new_road(env, straight_road(2, 1500.0, width_m=CROSSING_LANE_W, speed_limit=17.0))
    env.road = road
    speed = float(rng.uniform(20.0, 60.0)) / 3.6
    ego_y = CROSSING_LANE_W  # lane 1 centre
    env.make_ego(("0", "1", 1), 20.0, speed)
    left_kerb, right_kerb = -CROSSING_LANE_W / 2 - 2.6, ego_y + CROSSING_LANE_W / 2 + 2.6
    x = 20.0
    first_side = int(rng.integers(2))
    for k in range(3):
        x += float(rng.uniform(80.0, 110.0))
        from_left = bool((k + first_side) % 2)  # alternate sides
        y0, heading = (left_kerb, np.pi / 2) if from_left else (right_kerb, -np.pi / 2)
        walk = 1.39  # 5 km/h
        # trigger so that, without braking, the person reaches the ego's path as the ego arrives
        reach_m = (ego_y - 1.0 - y0) if from_left else (y0 - ego_y - 1.0)
        trigger = x - speed * reach_m / walk - 2.0
        road.objects.append(Pedestrian(road, [x, y0], heading, height_m=float(rng.uniform(1.55, 1.9)),
                                       style=int(rng.integers(1 << 30)), walk_speed_mps=walk,
                                       walk_distance_m=right_kerb - left_kerb, trigger_x_m=trigger, crossing=True))
    for k in range(4):
        px = float(rng.uniform(60.0, 600.0))
        y0 = left_kerb - 0.6 if rng.random() < 0.5 else right_kerb + 0.6
        walking = rng.random() < 0.6
        heading = 0.0 if rng.random() < 0.5 else np.pi
        road.objects.append(Pedestrian(road, [px, y0], heading, height_m=float(rng.uniform(1.5, 1.95)),
                                       style=int(rng.integers(1 << 30)), walk_speed_mps=1.2 if walking else 0.0,
                                       crossing=False))
    return road


LANDMARK_SPACING_M = 80.0
SIGN_OFFSET_M = 4.0


def build_loop(env, rng) -> Road:
    """A ~3.7 km circuit with ArUco signs at surveyed positions every 80 m, alternating sides."""
    net = loop_road()
    road = new_road(env, net)
    env.road = road
    env.make_ego(("0", "1", 1), 30.0, 22.0)
    place_traffic(road, rng, [0, 1], 0.0, 3000.0, 12, (20.0, 24.0), [(1, 0.0, 120.0)])
    nodes = chain_nodes(net)
    total = sum(net.graph[a][b][0].length for a, b in zip(nodes, nodes[1:] + ["0"]))
    n = int(total // LANDMARK_SPACING_M)
    for k in range(n):
        s = k * LANDMARK_SPACING_M + 20.0
        outer_lane = 0 if k % 2 == 0 else 1
        idx, ss = lane_at(net, outer_lane, s)
        lane = net.get_lane(idx)
        # outside the paved edge: half a lane, the shoulder, then the offset (lateral < 0 is left in highway-env)
        lat = (-1 if outer_lane == 0 else 1) * (lane.width / 2 + 1.8 + SIGN_OFFSET_M)
        pos = lane.position(ss, lat)
        # the face looks back down the road, turned 15 degrees towards the carriageway
        heading = lane.heading_at(ss) + np.pi + (-1 if outer_lane == 0 else 1) * np.radians(15)
        road.objects.append(Sign(road, pos, heading, marker_id=k))
    return road


SCENARIOS: dict[str, Scenario] = {s.name: s for s in [
    Scenario("highway", "4-lane straight highway, IDM traffic at 25-30 m/s, a lead vehicle in the ego lane", 40.0,
             build_highway, 25.0),
    Scenario("curves", "3-lane winding road: arcs of radii 150-600 m both ways, joined by clothoids, traffic", 60.0,
             build_curves, 20.0),
    Scenario("lead-brake", "following a lead at 24 m/s that brakes at -6 m/s^2 to a stop", 25.0, build_lead_brake,
             25.0),
    Scenario("cut-in", "a vehicle from the next lane cuts in 12-20 m ahead; the ego falls back to its time gap", 40.0,
             build_cut_in, 25.0),
    Scenario("cut-in-close", "a car 14 m/s slower pulls out 10-12 m ahead: only swerving into the free lane avoids "
             "it; odd seeds: that lane is taken and only full braking does", 25.0, build_cut_in_close, 25.0,
             watch_beside=True),
    Scenario("crossing", "pedestrians cross the ego lane at 5 km/h from both sides, others stay on the verge; "
             "ego at 20-60 km/h", 70.0, build_crossing, 12.0),
    Scenario("loop", "a 3.7 km closed circuit with ArUco landmark signs at surveyed positions", 160.0, build_loop,
             22.0),
    Scenario("dense", "highway-v0's traffic: 4 lanes, 50 cars at 20-30 m/s changing lanes (MOBIL); ego set to 30 m/s",
             40.0, build_dense, 25.0, lane_changes=True),
    Scenario("overtake", "3 lanes: a slow car ahead, faster traffic passing on the left, a car sitting beside the ego "
             "where no camera sees it", 40.0, build_overtake, 25.0, lane_changes=True),
    Scenario("merge", "highway-env's merge: ramp cars join the ego lane, two ahead of the ego, one behind; lane "
             "changes", 40.0, build_merge, 25.0, lane_changes=True),
]}
