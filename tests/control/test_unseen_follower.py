"""A follower beyond the rear view: with no follower in view in the target lane, MOBIL's safety test assumes one at
the view's edge going as fast as the ego went lately (``LaneChangeConfig.unseen_window_s``)."""

import pytest

from percept.control import LaneChange, LaneChangeConfig, idm_accel, judge
from percept.sensors import Neighbours

from .test_lane_change import DT, around, car, path

SLOW = 14.0  # the ego's speed behind a slow car [m/s]


def test_an_unseen_follower_closing_fast_from_the_views_edge_makes_an_empty_lane_unsafe():
    nb = around(car(0, 20.0, rel=-1.0))
    fast = judge(1, True, nb, SLOW, 30.0, unseen_speed_mps=26.0)
    # a car at 26 m/s, behind_m back, closing at 12 m/s: IDM brakes it by (s* / s)^2 a, more than b_safe
    assert fast.reason == "unseen follower" and not fast.safe
    assert fast.imposed_mps2 == pytest.approx(idm_accel(26.0, 26.0, nb.behind_m, 12.0)) and fast.imposed_mps2 < -2.0
    # one at the ego's own speed imposes little; without the assumption the empty lane is free
    assert judge(1, True, nb, SLOW, 30.0, unseen_speed_mps=SLOW).go
    assert judge(1, True, nb, SLOW, 30.0).go


def test_a_follower_in_view_stands_for_whatever_is_beyond_it():
    nb = around(car(0, 20.0, rel=-1.0), car(1, -40.0, rel=0.0, track_id=2))
    assert judge(1, True, nb, SLOW, 30.0, unseen_speed_mps=40.0).go


def test_a_change_waits_while_the_traffic_the_ego_braked_out_of_may_come_from_beyond_the_view():
    law = LaneChange(30.0, LaneChangeConfig(settle_s=0.5, unseen_window_s=4.0))
    slow = around(car(0, 20.0, rel=-1.0))
    reasons, started = [], None
    for k in range(int(8.0 / DT)):
        v = 26.0 if k < 15 else SLOW  # a second at 26 m/s on a free road, then braked down behind a slow car
        _, dbg = law.update(path(beside=(True, False), speed=v), around() if k < 15 else slow, v, DT)
        reasons.append(dbg.reason)
        if dbg.event == "started":
            started = k
            break
    assert "left: unseen follower; right: no lane" in reasons[15:30]
    # the ego's 26 m/s is forgotten unseen_window_s after it braked; the change then settles and starts
    assert started is not None and (started - 15) * DT == pytest.approx(4.0 + 0.5, abs=0.2)


def test_at_a_steady_speed_the_follower_assumed_beyond_the_view_holds_nothing_back():
    law = LaneChange(30.0, LaneChangeConfig(settle_s=0.5, unseen_window_s=4.0))
    slow = around(car(0, 20.0, rel=-1.0))
    events = [law.update(path(beside=(True, False), speed=SLOW), slow, SLOW, DT)[1].event for _ in range(15)]
    assert events.index("started") * DT == pytest.approx(0.5, abs=0.1)
