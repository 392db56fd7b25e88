"""OdometrySlot: the vision odometry slot. Stereo VO, IMU and wheel speed in an EKF, landmark fixes from the map.

Three filters run side by side on the same samples so that every run reports them together: dead reckoning
(IMU + wheel speed), fused (+ visual odometry) and the slot's estimate (+ landmark fixes); a fourth trajectory
chains the visual odometry alone.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from percept.sensors import (Frame, LandmarkMap, Lead, Pose2D, PoseEstimate, Side, StereoRig, as_sample,
                             plausible_speed, plausible_yaw_rate)

from .fusion import FusionNoise, PoseFilter
from .landmarks import LandmarkFinder, LandmarkSighting
from .stereo_vo import StereoVO
from .types import VOStep


FEW_INLIERS = 40
GOOD_SHARE = 0.5
CLEAN_NOISE_GREY = 1.0
"""A keyframe pose measured from n < FEW_INLIERS PnP inliers, or whose inliers are a share q < GOOD_SHARE of the
points tracked, or in images noisier than CLEAN_NOISE_GREY (sigma s, grey levels), has its standard deviations
widened by FEW_INLIERS / n, GOOD_SHARE / q and s / CLEAN_NOISE_GREY: such poses are biased (short of the truth at
night) beyond what their reprojection residuals show."""


@dataclass(frozen=True)
class OdometryDebug:
    """vo_pose: visual odometry alone, chained from the start pose; dead_reckoning_pose: IMU + wheel speed;
    fused_pose, fused_covariance (3, 3): IMU + wheel + VO without landmark fixes; vo_step: this frame's VO;
    sightings: mapped signs measured this frame; fixes: how many of them updated the estimate (the others
    failed the gate); landmark_fix: at least one did; rejected: sensor samples rejected so far (NaN, absurd)."""

    vo_pose: Pose2D
    dead_reckoning_pose: Pose2D
    fused_pose: Pose2D
    fused_covariance: np.ndarray
    vo_step: VOStep
    sightings: tuple[LandmarkSighting, ...]
    fixes: int
    rejected: int

    @property
    def landmark_fix(self) -> bool:
        return self.fixes > 0


def _planar(T: np.ndarray) -> tuple[float, float, float]:
    return float(T[0, 3]), float(T[1, 3]), math.atan2(T[1, 0], T[0, 0])


class OdometrySlot:
    """The odometry slot of one run. rig: the stereo rig; dt_s: frame period [s]; landmarks: the map (None: no
    fixes); start: the known start pose; noise: the filters' noise model."""

    def __init__(self, rig: StereoRig, dt_s: float, landmarks: LandmarkMap | None, start: Pose2D,
                 noise: FusionNoise = FusionNoise()):
        self.rig, self.dt_s, self.start, self.noise = rig, dt_s, start, noise
        self.vo = StereoVO(rig.camera.K, rig.baseline_m, rig.mount_height_m)
        self.finder = LandmarkFinder(rig, landmarks) if landmarks is not None and len(landmarks) else None
        T_cv = rig.cam_from_vehicle(Side.LEFT).matrix()
        self._T_cv, self._T_vc = T_cv, np.linalg.inv(T_cv)
        # vehicle (dx, dy, dyaw) from camera (rx, ry, rz, tx, ty, tz): dx = tz, dy = -tx + mount_x dyaw, dyaw = -ry
        J = np.zeros((3, 6))
        J[0, 5], J[1, 3], J[1, 1], J[2, 1] = 1.0, -1.0, -rig.mount_x_m, -1.0
        self._J = J
        self.reset()

    def reset(self) -> None:
        self.vo.reset()
        # without landmarks, VO's systematic errors cannot be told from the gyro bias and the wheel scale: the
        # fused filter leaves them out (the better accuracy, for an over-confident heading on long runs); the
        # estimate, whose landmark fixes make them observable, carries them
        plain = replace(self.noise, vo_scale_sigma=0.0, vo_yaw_drift_sigma_rad_per_m=0.0)
        self.dead_reckoning = PoseFilter(self.start, plain)
        self.fused = PoseFilter(self.start, plain)
        self.estimate = PoseFilter(self.start, self.noise)
        self._vo_T = self.start.world_from_vehicle().matrix()
        self._last_motion = np.eye(4)
        self._frames = 0
        self._since_image = 1  # frames since the last image VO saw

    @property
    def filters(self) -> tuple[PoseFilter, ...]:
        return self.dead_reckoning, self.fused, self.estimate

    def step(self, frame: Frame, upstream: dict) -> tuple[PoseEstimate, OdometryDebug]:
        # this frame's readings, once (NaN when missing; each filter and the VO prior judge them alike)
        w, a, v = as_sample(frame.imu.gyro_rps[2]), as_sample(frame.imu.accel_mps2[0]), as_sample(frame.wheel_speed_mps)
        for f in self.filters:
            if self._frames:
                f.predict(w, a, self.dt_s)
            f.update_wheel(v)
        self._frames += 1
        # the left image in grey, shared with the other slots, for VO and the sign search (the right one only where
        # they read it: a keyframe's stereo matches, a sign's window)
        left = frame.left_gray
        vo = self._visual_odometry(frame, left, upstream, self._prior(w, v))
        sightings: list[LandmarkSighting] = []
        fixes = 0
        if self.finder is not None and left is not None and frame.right is not None:
            sightings = self.finder.sight(left, frame.right_gray_or_bgr(), self.estimate.pose,
                                          self.estimate.pose_covariance)
            for s in sightings:
                fixes += self.estimate.update_landmark(self.finder.map.position(s.marker_id)[:2], s.position_v_m[:2],
                                                       s.covariance_xy)
        est = self.estimate
        debug = OdometryDebug(Pose2D(*_planar(self._vo_T)), self.dead_reckoning.pose, self.fused.pose,
                              self.fused.pose_covariance, vo, tuple(sightings), fixes,
                              sum(f.rejected for f in self.filters))
        return PoseEstimate(est.pose, est.speed_mps, est.pose_covariance, True), debug

    def _visual_odometry(self, frame: Frame, left: np.ndarray | None, upstream: dict,
                         prior: np.ndarray | None) -> VOStep:
        """VO on this frame's pair guided by ``prior`` (``_prior``; the lead's box, from the longitudinal slot, left
        out: it moves); the VO-only chain takes every step, the filters the pose against the last keyframe when the
        keyframe changes (one independent measurement per keyframe span)."""
        lead = upstream.get(Lead)
        step = self.vo.process(left, frame.right_gray_or_bgr(), prior, [getattr(lead, "box_px", None)])
        if left is None or frame.right is None:
            self._since_image += 1
            return step  # dropped: the next image's motion is measured from the last image
        self._since_image = 1
        if step.ok:
            self._last_motion = self._vehicle(step.T_prev_cur)
        # VO alone: a lost step is bridged with the last measured motion (constant velocity)
        self._vo_T = self._vo_T @ (self._last_motion if self._frames > 1 else np.eye(4))
        if step.keyframe:
            if step.ok and step.T_key_cur is not None:
                dx, dy, dyaw = _planar(self._vehicle(step.T_key_cur))
                # a pose from few inliers, or from a small share of the tracked points (night, rain), is biased
                # beyond what its residuals say: widen it
                widen = max(1.0, FEW_INLIERS / max(step.inliers, 1)) * max(1.0, GOOD_SHARE / max(step.quality, 0.01))
                widen *= max(1.0, (step.noise_grey or 0.0) / CLEAN_NOISE_GREY)
                cov = self._J @ step.key_covariance @ self._J.T * widen ** 2
                for f in (self.fused, self.estimate):
                    f.update_relative(dx, dy, dyaw, cov)
            for f in (self.fused, self.estimate):
                f.clone()
        return step

    def _prior(self, w: float, v: float) -> np.ndarray | None:
        """The camera motion since the last image that the wheel speed ``v`` [m/s] and the gyro's yaw rate ``w``
        [rad/s] alone predict (None before the first image or without a plausible sample): independent of the
        visual odometry it guides, so that a biased VO cannot select the points that confirm its bias."""
        if self._frames <= 1 or not (plausible_yaw_rate(w) and plausible_speed(v)):
            return None
        dt = self._since_image * self.dt_s
        # planar motion at constant speed and yaw rate: the heading turns by w dt, the chord lies at half of it
        c, s = math.cos(w * dt), math.sin(w * dt)
        T = np.array([[c, -s, 0.0, v * dt * math.cos(w * dt / 2)], [s, c, 0.0, v * dt * math.sin(w * dt / 2)],
                      [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
        return self._T_cv @ T @ self._T_vc

    def _vehicle(self, T_cam: np.ndarray) -> np.ndarray:
        """Camera motion -> the vehicle's: T_v = T_vc T_c T_cv."""
        return self._T_vc @ T_cam @ self._T_cv
