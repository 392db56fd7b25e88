"""Pose fusion: an extended Kalman filter (filterpy) over planar pose, speed, gyro and accelerometer biases and the
wheel-speed scale.

The IMU (yaw rate, forward acceleration) predicts through the kinematic bicycle model (the vehicle centre's
velocity leans from the heading by the slip angle in a turn; Rajamani, *Vehicle Dynamics and Control*, sec. 2.2);
the wheel speed, visual odometry and landmark fixes update. Visual odometry measures the motion between two images,
so the filter keeps a copy of the pose at the last keyframe (stochastic cloning: Roumeliotis & Burdick 2002,
"Stochastic cloning: a generalized framework for processing relative state measurements", ICRA) and updates with
the relative pose between the copy and now. A NaN or absurd sensor sample is rejected, never propagated: the
prediction then uses the last good reading with its uncertainty widened. References: Thrun, Burgard & Fox,
*Probabilistic Robotics*, ch. 3 and 7 (EKF, landmark updates); Bar-Shalom, Li & Kirubarajan 2001, sec. 5.4
(normalised innovation gating).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from filterpy.kalman import ExtendedKalmanFilter

from percept.sensors import Pose2D, plausible_accel, plausible_speed, plausible_yaw_rate, wrap_angle
from percept.sensors.vehicle import WHEELBASE_M

# state: pose (x, y, yaw), speed, gyro bias, wheel scale, accelerometer bias, visual odometry's scale error and
# yaw drift per metre, then the clone of the pose at the last keyframe
X, Y, YAW, V, BG, KW, BA, SV, BV, XC, YC, YAWC = range(12)
N_STATE = 12
# 99 % gates of the normalised innovation squared: chi2 with 2 and 3 degrees of freedom
GATE_CHI2 = {2: 9.21, 3: 11.34}


@dataclass(frozen=True)
class FusionNoise:
    """Noise model of ``PoseFilter``: the sensors' white noise, the random walks and priors of their biases, and the
    scaling of visual odometry's own covariance."""

    gyro_sigma_rps: float = 0.003  # white noise of one gyro sample [rad/s]
    accel_sigma_mps2: float = 0.08  # white noise of one accelerometer sample [m/s²]
    gyro_bias_walk: float = 0.0003  # random walk of the gyro bias [rad/s/sqrt(s)]
    wheel_sigma_mps: float = 0.07  # white noise of one wheel-speed sample [m/s]
    wheel_scale_sigma: float = 0.015  # prior std of the wheel scale error [1]
    init_bias_sigma_rps: float = 0.002  # prior std of the gyro bias [rad/s]
    accel_bias_walk: float = 0.003  # random walk of the accelerometer bias [m/s²/sqrt(s)]
    init_accel_bias_mps2: float = 0.02  # prior std of the accelerometer bias [m/s²]
    vo_scale_sigma: float = 0.003  # prior std of visual odometry's translation scale error [1]
    vo_yaw_drift_sigma_rad_per_m: float = 2e-5  # prior std of visual odometry's yaw drift [rad/m travelled]
    # without landmarks the VO errors are unobservable: their covariance grows with the distance, as it should
    vo_bias_walk: float = 0.2  # random walk of both VO errors, relative to their prior std [1/sqrt(s)]
    # VO's covariance comes from the reprojection residuals alone and leaves out the keyframe points' depth error
    vo_scale_translation: float = 9.0  # factor on VO's translation variances
    vo_scale_rotation: float = 4.0  # factor on VO's yaw variance
    # added to every keyframe span's motion whatever its residuals say: their covariance varies far more from span
    # to span than the spans' true errors, and one over-confident span would set the speed wrong and make the gate
    # refuse the spans after it
    vo_step_floor: tuple[float, float, float] = (0.03, 0.015, 1.5e-4)  # span std: along, across [m], yaw [rad]
    lockout_sightings: int = 3  # landmark sightings refused in a row before the pose variances are widened
    lockout_widen: float = 4.0  # factor on the pose variances after such a lock-out


class _Ekf(ExtendedKalmanFilter):
    """filterpy's EKF with the kinematic bicycle's state prediction (``slip_arm_m`` set by the owner)."""

    slip_arm_m = WHEELBASE_M / 2

    def predict_x(self, u=None) -> None:
        yaw_rate, accel, dt = u
        x = self.x
        # the state's elements as Python floats (the same doubles, without numpy's scalar overhead)
        v, yaw = x.item(V), x.item(YAW)
        w = yaw_rate - x.item(BG)
        course = yaw + slip_angle(w, v, self.slip_arm_m)
        # the centre moves along heading + slip for one step, then the heading and speed change (explicit Euler,
        # as the vehicle model integrates): p += v dt (cos, sin)(psi + beta); psi += w dt; v += (a - b_a) dt
        x[X, 0] = x.item(X) + v * dt * math.cos(course)
        x[Y, 0] = x.item(Y) + v * dt * math.sin(course)
        x[YAW, 0] = wrap_angle(yaw + w * dt)
        x[V, 0] = max(v + (accel - x.item(BA)) * dt, 0.0)


def slip_angle(yaw_rate_rps: float, speed_mps: float, arm_m: float) -> float:
    """Kinematic bicycle: the centre's velocity leans from the heading by beta, sin(beta) = r l_r / v, with l_r
    the centre's distance to the rear axle (whose velocity is along the heading) [rad]."""
    return math.asin(max(-0.5, min(0.5, yaw_rate_rps * arm_m / max(speed_mps, 1.0))))


def _angle_residual(index: int):
    def residual(a: np.ndarray, b: np.ndarray) -> np.ndarray:
        r = a - b
        r[index] = wrap_angle(r[index])
        return r
    return residual


_ANGLE_RESIDUAL = {2: _angle_residual(2)}  # the residual of a measurement whose element 2 is an angle


def _wheel_speed(s: np.ndarray) -> np.ndarray:
    """The wheel speed the state ``s`` (12, 1) predicts: scale x speed, (1, 1) [m/s]."""
    return np.array([[s.item(KW) * s.item(V)]])


def _wheel_jacobian(s: np.ndarray) -> np.ndarray:
    """(1, 12) d(k_w v) / ds: k_w for the speed, v for the scale."""
    h = np.zeros((1, N_STATE))
    h[0, V], h[0, KW] = s.item(KW), s.item(V)
    return h


def _relative_motion(s: np.ndarray) -> np.ndarray:
    """The motion since the clone that the state ``s`` (12, 1) predicts, (3, 1) (dx, dy [m], dyaw [rad]) in the
    clone's vehicle frame."""
    c, sn = math.cos(s.item(YAWC)), math.sin(s.item(YAWC))
    d0, d1 = s.item(X) - s.item(XC), s.item(Y) - s.item(YC)
    k = 1.0 + s.item(SV)
    # [dx, dy] = (1 + s_vo) R(-psi_c) (p - p_c); dyaw = psi - psi_c + b_vo |p - p_c|
    return np.array([[k * (c * d0 + sn * d1)], [k * (-sn * d0 + c * d1)],
                     [wrap_angle(s.item(YAW) - s.item(YAWC)) + s.item(BV) * math.hypot(d0, d1)]])


class PoseFilter:
    """Planar pose, speed, gyro and accelerometer biases and wheel scale from IMU + wheel speed, updated by visual
    odometry's relative motion and by landmark positions. ``start``: the known start pose; speed starts from the
    first wheel reading."""

    def __init__(self, start: Pose2D, noise: FusionNoise = FusionNoise()):
        self.noise = noise
        self.kf = _Ekf(N_STATE, 3)
        self.kf.x = np.zeros((N_STATE, 1))
        self.kf.x[[X, Y, YAW], 0] = (start.x_m, start.y_m, start.yaw_rad)
        self.kf.x[KW, 0] = 1.0
        self.kf.P = np.diag([1e-6, 1e-6, 1e-8, 1.0, noise.init_bias_sigma_rps ** 2, noise.wheel_scale_sigma ** 2,
                             noise.init_accel_bias_mps2 ** 2, noise.vo_scale_sigma ** 2,
                             noise.vo_yaw_drift_sigma_rad_per_m ** 2, 1e-6, 1e-6, 1e-8])
        self._last_input = (0.0, 0.0)
        self._started = False
        self._F = np.eye(N_STATE)  # the step's Jacobian: its off-diagonal terms are rewritten by every prediction
        self._Q: dict[tuple[float, bool], np.ndarray] = {}  # process noise by (dt, good sample)
        self._wheel_R = np.array([[noise.wheel_sigma_mps ** 2]])
        # visual odometry's covariance scaled: Sigma = D Sigma_vo D, D = diag(sqrt(k_t), sqrt(k_t), sqrt(k_r)), by
        # elements Sigma_vo * (d d^T)
        d = np.sqrt([noise.vo_scale_translation, noise.vo_scale_translation, noise.vo_scale_rotation])
        self._vo_D2 = np.outer(d, d)
        # ... plus the floor's variances on the diagonal
        self._vo_floor = np.diag(np.square(noise.vo_step_floor))
        self.rejected = 0  # sensor samples rejected as NaN or absurd
        self.gated = 0  # measurements refused by the innovation gate
        self._refused = 0  # landmark sightings refused in a row

    @property
    def pose(self) -> Pose2D:
        x = self.kf.x[:, 0]
        return Pose2D(float(x[X]), float(x[Y]), float(x[YAW]))

    @property
    def speed_mps(self) -> float:
        return float(self.kf.x[V, 0])

    @property
    def pose_covariance(self) -> np.ndarray:
        """(3, 3) covariance of (x_m, y_m, yaw_rad)."""
        return self.kf.P[:3, :3].copy()

    def predict(self, yaw_rate_rps: float, accel_mps2: float, dt: float) -> bool:
        """Propagate by ``dt`` [s] with one IMU sample; an absurd or NaN sample is replaced by the last good one
        (with widened noise) and False is returned."""
        good = plausible_yaw_rate(yaw_rate_rps) and plausible_accel(accel_mps2)
        if good:
            self._last_input = (yaw_rate_rps, accel_mps2)
        else:
            self.rejected += 1
        w, a = self._last_input
        x = self.kf.x
        xv, bg, arm = x.item(V), x.item(BG), self.kf.slip_arm_m
        v = max(xv, 1.0)
        beta = slip_angle(w - bg, xv, arm)
        c, s = math.cos(x.item(YAW) + beta), math.sin(x.item(YAW) + beta)
        # Jacobian of the step: d beta / d v = -r l_r / (v^2 cos beta), d beta / d b_g = -l_r / (v cos beta)
        db_dv, db_dbg = -(w - bg) * arm / (v * v * math.cos(beta)), -arm / (v * math.cos(beta))
        F = self._F
        F[X, YAW], F[X, V], F[X, BG] = -xv * dt * s, dt * c - xv * dt * s * db_dv, -xv * dt * s * db_dbg
        F[Y, YAW], F[Y, V], F[Y, BG] = xv * dt * c, dt * s + xv * dt * c * db_dv, xv * dt * c * db_dbg
        F[YAW, BG] = -dt
        F[V, BA] = -dt
        self.kf.F = F
        Q = self._Q.get((dt, good))
        if Q is None:
            Q = self._Q[dt, good] = self._process_noise(dt, 1.0 if good else 25.0)
        self.kf.Q = Q
        self.kf.predict(u=(w, a, dt))
        return good

    def _process_noise(self, dt: float, widen: float) -> np.ndarray:
        """(12, 12) process noise of a step of ``dt`` [s], the IMU's white noise variances times ``widen``."""
        n = self.noise
        Q = np.zeros((N_STATE, N_STATE))
        Q[YAW, YAW] = widen * (n.gyro_sigma_rps * dt) ** 2
        Q[V, V] = widen * (n.accel_sigma_mps2 * dt) ** 2
        Q[BG, BG] = n.gyro_bias_walk ** 2 * dt
        Q[KW, KW] = 1e-10 * dt
        Q[BA, BA] = n.accel_bias_walk ** 2 * dt
        Q[SV, SV] = (n.vo_bias_walk * n.vo_scale_sigma) ** 2 * dt
        Q[BV, BV] = (n.vo_bias_walk * n.vo_yaw_drift_sigma_rad_per_m) ** 2 * dt
        return Q

    def update_wheel(self, wheel_speed_mps: float) -> bool:
        """Wheel speed = scale x speed. Rejects NaN and absurd readings (returns False)."""
        if not plausible_speed(wheel_speed_mps):
            self.rejected += 1
            return False
        if not self._started:
            self.kf.x[V, 0] = max(wheel_speed_mps, 0.0)
            self._started = True
        self.kf.update(np.array([[wheel_speed_mps]]), _wheel_jacobian, _wheel_speed, R=self._wheel_R)
        return True

    def clone(self) -> None:
        """Remember the current pose as the one of the last processed image (with its correlations)."""
        x, P = self.kf.x, self.kf.P
        # the clone's (XC, YC, YAWC) and the pose's (X, Y, YAW) are each three consecutive elements
        x[XC:YAWC + 1] = x[X:YAW + 1]
        P[XC:YAWC + 1, :] = P[X:YAW + 1, :]
        P[:, XC:YAWC + 1] = P[:, X:YAW + 1]

    def update_relative(self, dx_m: float, dy_m: float, dyaw_rad: float, cov: np.ndarray) -> bool:
        """Visual odometry: the vehicle's motion since the clone, in the clone's vehicle frame (dx forward, dy
        left [m], dyaw [rad]) with its (3, 3) covariance. Gated; False when rejected."""
        x = self.kf.x
        c, sn = math.cos(x.item(YAWC)), math.sin(x.item(YAWC))
        d0, d1 = x.item(X) - x.item(XC), x.item(Y) - x.item(YC)
        base0, base1 = c * d0 + sn * d1, -sn * d0 + c * d1
        k = 1.0 + x.item(SV)
        Hm = np.zeros((3, N_STATE))
        Hm[0, X], Hm[0, Y], Hm[0, XC], Hm[0, YC] = k * c, k * sn, -k * c, -k * sn
        Hm[0, YAWC], Hm[0, SV] = k * base1, base0
        Hm[1, X], Hm[1, Y], Hm[1, XC], Hm[1, YC] = -k * sn, k * c, k * sn, -k * c
        Hm[1, YAWC], Hm[1, SV] = -k * base0, base1
        # d dyaw / d b_vo = |p - p_c| (its dependence on the positions, b_vo d|d|/dp, is negligible)
        Hm[2, YAW], Hm[2, YAWC], Hm[2, BV] = 1.0, -1.0, math.hypot(d0, d1)
        return self._gated_update(np.array([[dx_m], [dy_m], [dyaw_rad]]), Hm, _relative_motion,
                                  cov * self._vo_D2 + self._vo_floor, 2)

    def update_landmark(self, landmark_xy_m: np.ndarray, measured_xy_m: np.ndarray, cov: np.ndarray) -> bool:
        """A mapped landmark at world ``landmark_xy_m`` (2,) seen at ``measured_xy_m`` (2,) in the vehicle frame
        with (2, 2) covariance. Gated against wrong matches; False when rejected."""
        L = np.asarray(landmark_xy_m, float)
        lx, ly = L.item(0), L.item(1)
        yaw = self.kf.x.item(YAW)
        c, sn = math.cos(yaw), math.sin(yaw)

        def hx(s):
            cc, ss = math.cos(s.item(YAW)), math.sin(s.item(YAW))
            d0, d1 = lx - s.item(X), ly - s.item(Y)
            # landmark in the vehicle frame: R(-psi) (L - p)
            return np.array([[cc * d0 + ss * d1], [-ss * d0 + cc * d1]])

        h = hx(self.kf.x)
        Hm = np.zeros((2, N_STATE))
        Hm[0, X], Hm[0, Y], Hm[0, YAW] = -c, -sn, h.item(1)
        Hm[1, X], Hm[1, Y], Hm[1, YAW] = sn, -c, -h.item(0)
        accepted = self._gated_update(np.asarray(measured_xy_m, float).reshape(2, 1), Hm, hx, cov, None)
        self._refused = 0 if accepted else self._refused + 1
        if self._refused >= self.noise.lockout_sightings:
            # gate lock-out: consistent sightings keep disagreeing with an estimate that is too sure of itself;
            # widen its pose uncertainty so that the next one can pull it back
            self.kf.P[[X, Y, YAW], [X, Y, YAW]] *= self.noise.lockout_widen
            self._refused = 0
        return accepted

    def _gated_update(self, z: np.ndarray, Hm: np.ndarray, hx, R: np.ndarray, angle_index: int | None) -> bool:
        if not (np.isfinite(z).all() and np.isfinite(R).all()):
            self.rejected += 1
            return False
        y = z - hx(self.kf.x)
        if angle_index is not None:
            y[angle_index] = wrap_angle(y[angle_index])
        S = Hm @ self.kf.P @ Hm.T + R
        # normalised innovation squared y^T S^-1 y against chi2 at 99 %
        if float((y.T @ np.linalg.solve(S, y))[0, 0]) > GATE_CHI2[len(z)]:
            self.gated += 1
            return False
        residual = _ANGLE_RESIDUAL[angle_index] if angle_index is not None else np.subtract
        self.kf.update(z, lambda _s: Hm, hx, R=R, residual=residual)
        return True
