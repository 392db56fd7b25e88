"""The lead's range filter: closing speed from ranges alone, the gate, the floor on the range rate."""

import numpy as np
import pytest

from percept.longitudinal import RangeFilter
from percept.longitudinal.range_filter import RANGE, RATE

DT = 1 / 15


def test_a_lead_closing_at_constant_speed_gives_its_range_rate_from_ranges_alone():
    f = RangeFilter(50.0, 0.2, DT, 8.0)
    for k in range(1, 60):
        f.predict(-np.inf)
        # range closing at 5 m/s: z = 50 - 5 t
        assert f.gated_update(50.0 - 5.0 * k * DT, 0.2, RANGE, 5.0)
    assert f.rate_mps == pytest.approx(-5.0, abs=0.3)
    assert f.range_m == pytest.approx(50.0 - 5.0 * 59 * DT, abs=0.2)


def test_a_measurement_beyond_the_gate_is_refused_and_changes_nothing():
    f = RangeFilter(30.0, 0.1, DT, 8.0)
    f.predict(-np.inf)
    before = f.kf.x.copy(), f.kf.P.copy()
    # the range's sigma after one prediction is ~0.1 m: 20 m off is far beyond 5 sigma
    assert not f.gated_update(50.0, 0.1, RANGE, 5.0)
    assert np.array_equal(f.kf.x, before[0]) and np.array_equal(f.kf.P, before[1])  # not touched at all
    # a rate measurement is gated on the rate's own variance (10 m/s at the start): 3 m/s passes
    assert f.gated_update(-3.0, 0.5, RATE, 5.0)
    assert f.rate_mps == pytest.approx(-3.0, abs=0.1)


def test_the_range_rate_is_held_at_its_floor_by_projecting_the_estimate():
    f = RangeFilter(20.0, 0.1, DT, 8.0)
    f.predict(-np.inf)
    assert f.gated_update(-9.0, 0.2, RATE, 5.0)
    assert f.rate_mps < -8.0
    # the unconstrained prediction, then its projection onto rate >= -3 (the ego at 2 m/s, plus 1 m/s):
    # x <- x - P[:, 1] / P[1, 1] (x[1] - floor)
    x = f.kf.F @ f.kf.x
    P = f.kf.F @ f.kf.P @ f.kf.F.T + f.kf.Q
    expected = x - P[:, 1:2] / P[1, 1] * (x[1, 0] + 3.0)
    f.predict(-3.0)
    assert f.rate_mps == pytest.approx(-3.0, abs=1e-6)  # [m/s]
    assert np.allclose(f.kf.x, expected, rtol=0, atol=1e-6)
    # the range moved with the rate (they are correlated), away from where the rate alone would put it
    assert f.range_m != pytest.approx(float(x[0, 0]), abs=1e-3)
    # a floor the estimate is above changes nothing
    g = RangeFilter(20.0, 0.1, DT, 8.0)
    g.predict(-30.0)
    assert g.rate_mps == 0.0 and g.range_m == 20.0


def test_a_manoeuvre_takes_the_range_whatever_its_innovation_and_opens_the_rate():
    f = RangeFilter(30.0, 0.1, DT, 8.0)
    for _ in range(20):
        f.predict(-np.inf)
        f.gated_update(30.0, 0.1, RANGE, 5.0)
    var_rate = f.kf.P[RATE, RATE]
    assert not f.gated_update(28.0, 0.1, RANGE, 5.0)
    f.manoeuvre(28.0, 0.1, 5.0, 6.0)
    # its range variance doubled and more: the measurement pulls the range more than half way
    assert 28.0 < f.range_m < 29.0
    assert f.kf.P[RATE, RATE] > var_rate
