"""The one rule for bad ego-motion samples: the predicates and the gate that holds the last plausible sample."""

import math

import numpy as np
import pytest

from percept.sensors import (MAX_SPEED_MPS, MAX_YAW_RATE_RPS, EgoMotionGate, Frame, ImuSample, plausible_accel,
                             plausible_speed, plausible_yaw_rate)


def frame(speed, yaw_rate, index=0) -> Frame:
    return Frame(index, index / 15, None, None, ImuSample(np.zeros(3), np.array([0.0, 0.0, yaw_rate])), speed)


@pytest.mark.parametrize("v, ok", [(0.0, True), (33.0, True), (-0.5, True), (MAX_SPEED_MPS, True),
                                   (MAX_SPEED_MPS + 1, False), (-5.0, False), (math.nan, False), (math.inf, False)])
def test_plausible_speed(v, ok):
    assert plausible_speed(v) is ok


@pytest.mark.parametrize("w, ok", [(0.0, True), (-0.4, True), (MAX_YAW_RATE_RPS, True),
                                   (-MAX_YAW_RATE_RPS - 0.1, False), (math.nan, False), (-math.inf, False)])
def test_plausible_yaw_rate(w, ok):
    assert plausible_yaw_rate(w) is ok


def test_plausible_accel():
    assert plausible_accel(-8.0) and not plausible_accel(45.0) and not plausible_accel(math.nan)


def test_gate_holds_the_last_plausible_sample_of_each_signal_on_its_own():
    gate = EgoMotionGate()
    first = gate.update(frame(math.nan, math.nan))
    assert (first.speed_mps, first.yaw_rate_rps, first.speed_ok, first.yaw_rate_ok) == (0.0, 0.0, False, False)
    good = gate.update(frame(20.0, 0.1, 1))
    assert (good.speed_mps, good.yaw_rate_rps, good.speed_ok, good.yaw_rate_ok) == (20.0, 0.1, True, True)
    # a bad speed keeps 20 m/s while the yaw rate moves on, and the other way round
    m = gate.update(frame(math.nan, 0.2, 2))
    assert (m.speed_mps, m.yaw_rate_rps, m.speed_ok, m.yaw_rate_ok) == (20.0, 0.2, False, True)
    m = gate.update(frame(21.0, 50.0, 3))
    assert (m.speed_mps, m.yaw_rate_rps, m.speed_ok, m.yaw_rate_ok) == (21.0, 0.2, True, False)
    # a wheel speed that is not a number at all (a missing sample) is a bad one too
    m = gate.update(frame(None, 0.2, 4))
    assert m.speed_mps == 21.0 and not m.speed_ok
    gate.reset()
    m = gate.update(frame(500.0, math.inf, 5))
    assert (m.speed_mps, m.yaw_rate_rps) == (0.0, 0.0)
