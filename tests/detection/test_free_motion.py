"""A track's free motion: a plain filterpy update inside the gate, a down-weighted one beyond it, the hysteresis."""

import numpy as np
import pytest
from filterpy.common import Q_discrete_white_noise

from percept.detection import FreeMotion

DT = 1 / 15
F = np.block([[np.eye(2), np.eye(2) * DT], [np.zeros((2, 2)), np.eye(2)]])
Q = Q_discrete_white_noise(2, DT, 0.7 ** 2, block_size=2, order_by_dim=False)
B, U = np.zeros((4, 2)), np.zeros(2)
R = np.diag([1.5 ** 2, 0.3 ** 2])


def moving(speed_mps: float, frames: int, gate_chi2: float = 13.8) -> tuple[FreeMotion, float]:
    """A free motion fed ``frames`` exact detections of something moving away at ``speed_mps``; (it, x now)."""
    x = 30.0
    fm = FreeMotion(np.array([x, 2.0]), R, 30.0, gate_chi2, 8.0, 2.5)
    for _ in range(frames):
        fm.predict(F, Q, B, U)
        x += speed_mps * DT
        fm.update(np.array([x, 2.0]), R)
    return fm, x


def test_inside_the_gate_it_is_the_plain_kalman_update():
    gated, x = moving(15.0, 20)
    plain, _ = moving(15.0, 20, gate_chi2=np.inf)
    np.testing.assert_allclose(gated.kf.x, plain.kf.x)
    np.testing.assert_allclose(gated.kf.P, plain.kf.P)
    assert gated.speed[0] == pytest.approx(15.0, abs=0.5)


def test_a_detection_beyond_the_gate_moves_it_less_the_farther_it_lies():
    pulls = []
    for jump_m in (0.0, 3.0, 10.0, 16.0, 25.0):  # a taller window on the same car puts its feet nearer
        gated, x = moving(15.0, 20)
        plain, _ = moving(15.0, 20, gate_chi2=np.inf)
        for fm in (gated, plain):
            fm.predict(F, Q, B, U)
            fm.update(np.array([x + 15.0 * DT - jump_m, 2.0]), R)
        pulls.append((15.0 - gated.kf.x[2], 15.0 - plain.kf.x[2]))  # how far vx was pulled from 15 m/s
    (g0, p0), (g3, p3), *beyond = pulls
    assert g0 == pytest.approx(p0) and g3 == pytest.approx(p3) and g3 > 0.3  # inside the gate: the plain update
    assert all(g < p for g, p in beyond), pulls  # beyond the gate, down-weighted
    assert beyond[0][0] > beyond[1][0] > beyond[2][0], pulls  # and the farther, the less
    assert beyond[2][1] > 4.0 > 0.5 > beyond[2][0], pulls  # 25 m nearer: 15 m/s pulled to 10.5, gated to 14.5+


def test_too_fast_once_clearly_above_the_limit_and_a_person_again_only_once_clearly_below():
    fm, x = moving(15.0, 20)
    assert fm.too_fast
    for _ in range(3):  # it stops: still a vehicle until its speed stands clearly below 8 m/s
        fm.predict(F, Q, B, U)
        fm.update(np.array([x, 2.0]), R)
        speed, sigma = fm.speed
        assert fm.too_fast == (speed + 2.5 * sigma >= 8.0)
    for _ in range(60):
        fm.predict(F, Q, B, U)
        fm.update(np.array([x, 2.0]), R)
    assert not fm.too_fast and fm.speed[0] < 1.0
    slow, _ = moving(1.5, 30)
    assert not slow.too_fast and slow.speed[0] == pytest.approx(1.5, abs=0.5)
