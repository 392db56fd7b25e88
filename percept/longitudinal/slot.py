"""The vision longitudinal slot: the stereo pair and the ego path in, the lead out.

Each frame: the nearest obstacle standing in the path (``obstacles``), its subpixel disparity over the lower
part of it that faces the ego (``refine``), range Z = f b / d with the stereo noise sigma_Z = Z^2 sigma_d / (f b);
then a Kalman filter (filterpy) over range and range rate (constant velocity, white acceleration noise) with a
gate: a measurement far from the prediction twice in a row starts a new track (a cut-in, the lead changing
lanes). A track is reported once confirmed, kept through short misses and dropped frames, with a confidence
that falls while it is only predicted.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
from filterpy.kalman import KalmanFilter

from percept.sensors import EgoPath, Frame, Lead, ObjectKind, StereoRig

from .obstacles import Obstacle, ObstacleConfig, ObstacleFinder
from .refine import Refined, refine_disparity, surface_mask


@dataclass(frozen=True)
class LeadConfig:
    """face_m: heights above the road of the band whose disparity is refined (a vehicle's body faces the ego
    there) [m]; sigma_d_px: floor on the disparity noise [px] (the simulator renders object edges without
    anti-aliasing, so an edge's disparity is quantised to whole pixels: uniform error, sigma = 1/sqrt(12) px);
    accel_sigma_mps2: white acceleration noise of the lead's range [m/s²]; gate_sigma: innovations beyond this
    many sigma are outliers; confirm: hits before a track is reported; hold_s: how long a track is predicted
    without measurements [s]."""

    face_m: tuple[float, float] = (0.4, 0.9)
    sigma_d_px: float = 0.29
    accel_sigma_mps2: float = 3.0
    gate_sigma: float = 5.0
    confirm: int = 3
    hold_s: float = 0.6
    obstacles: ObstacleConfig = ObstacleConfig()


@dataclass(frozen=True)
class LeadDebug:
    """obstacle: this frame's nearest standing group (None if none); refined: its subpixel disparity; measured_m:
    the stereo range [m] (None without one); state: (range, range rate) after the update; hits, misses: the
    track's counts."""

    obstacle: Obstacle | None
    refined: Refined | None
    measured_m: float | None
    state: tuple[float, float] | None
    hits: int
    misses: int


class LongitudinalSlot:
    """Slot interface: ``reset()``, ``step(frame, upstream) -> (Lead | None, LeadDebug)``; reads the ego path
    (``upstream["lateral"]``, a straight corridor without it)."""

    def __init__(self, rig: StereoRig, dt_s: float, cfg: LeadConfig = LeadConfig()):
        self.rig, self.dt, self.cfg = rig, dt_s, cfg
        self.finder = ObstacleFinder(rig, cfg.obstacles)
        self.fb = rig.camera.fx * rig.baseline_m
        self.reset()

    def reset(self) -> None:
        self.kf: KalmanFilter | None = None
        self.hits = self.misses = self.outliers = 0
        self.box: tuple | None = None

    def step(self, frame: Frame, upstream: dict) -> tuple[Lead | None, LeadDebug]:
        path = upstream.get("lateral") or EgoPath.straight(frame.wheel_speed_mps)
        self._predict()
        ob = ref = z = None
        if not frame.dropped:
            left = cv2.cvtColor(frame.left, cv2.COLOR_BGR2GRAY)
            right = cv2.cvtColor(frame.right, cv2.COLOR_BGR2GRAY)
            ob, _ = self.finder.find(left, right, path)
            if ob is not None:
                ref = self._refine(left, right, ob)
                z = self.fb / ref.disparity_px if ref is not None and ref.disparity_px > 0.5 else ob.range_m
        self._update(z, ref, ob)
        state = None if self.kf is None else (float(self.kf.x[0, 0]), float(self.kf.x[1, 0]))
        return self._lead(), LeadDebug(ob, ref, z, state, self.hits, self.misses)

    def _refine(self, left: np.ndarray, right: np.ndarray, ob: Obstacle) -> Refined | None:
        """Subpixel disparity over the band of the obstacle that faces the ego (its lower body)."""
        cam, h = self.rig.camera, self.rig.mount_height_m
        lo, hi = self.cfg.face_m
        z0, d0 = ob.range_m, self.fb / ob.range_m
        # rows of heights hi..lo at range Z: v = cy + fy (h - z) / Z
        v0 = int(max(cam.cy + cam.fy * (h - hi) / z0, 0))
        v1 = int(min(cam.cy + cam.fy * (h - lo) / z0, cam.height))
        v1 = max(v1, v0 + 3)
        # only the crop the matching needs: the face, and the right image up to its disparity further left
        c0 = max(ob.box_px[0] - int(d0) - 8, 0)
        c1 = min(ob.box_px[2] + 2, cam.width)
        L, R = left[v0:v1, c0:c1].astype(np.float32), right[v0:v1, c0:c1].astype(np.float32)
        box = (ob.box_px[0] - c0, 0, ob.box_px[2] - c0, v1 - v0)
        m = surface_mask(L, R, box, d0)
        if m is None or m.sum() < 12:
            return None
        return refine_disparity(L, R, box, m, d0)

    def _predict(self) -> None:
        if self.kf is not None:
            self.kf.predict()

    def _new_track(self, z: float, sigma: float) -> None:
        kf = KalmanFilter(dim_x=2, dim_z=1)
        dt, q = self.dt, self.cfg.accel_sigma_mps2 ** 2
        kf.F = np.array([[1.0, dt], [0.0, 1.0]])
        kf.H = np.array([[1.0, 0.0]])
        # white acceleration: Q = q [[dt^4/4, dt^3/2], [dt^3/2, dt^2]]
        kf.Q = q * np.array([[dt ** 4 / 4, dt ** 3 / 2], [dt ** 3 / 2, dt ** 2]])
        kf.x = np.array([[z], [0.0]])
        kf.P = np.diag([sigma ** 2, 10.0 ** 2])
        self.kf, self.hits, self.misses, self.outliers = kf, 1, 0, 0

    def _update(self, z: float | None, ref: Refined | None, ob: Obstacle | None) -> None:
        if z is None:
            self.misses += 1
            if self.kf is not None and self.misses * self.dt > self.cfg.hold_s:
                self.reset()
            return
        sd = max(ref.sigma_px if ref is not None else 1.0, self.cfg.sigma_d_px)
        # stereo range noise: sigma_Z = Z^2 sigma_d / (f b)
        sigma = z * z * sd / self.fb
        self.box = ob.box_px
        if self.kf is None:
            self._new_track(z, sigma)
            return
        self.kf.R = np.array([[sigma ** 2]])
        s = float((self.kf.H @ self.kf.P @ self.kf.H.T + self.kf.R)[0, 0])
        innovation = z - float(self.kf.x[0, 0])
        if innovation * innovation > self.cfg.gate_sigma ** 2 * s:
            self.outliers += 1
            if self.outliers >= 2:  # the lead changed: follow the new one
                self._new_track(z, sigma)
            return
        self.kf.update(np.array([[z]]))
        self.hits, self.misses, self.outliers = self.hits + 1, 0, 0

    def _lead(self) -> Lead | None:
        if self.kf is None or self.hits < self.cfg.confirm:
            return None
        rng, rate = float(self.kf.x[0, 0]), float(self.kf.x[1, 0])
        confidence = max(0.0, 1.0 - self.misses * self.dt / self.cfg.hold_s)
        # whatever stands in the path is followed like a vehicle; people are the pedestrian slot's to yield to
        return Lead(rng, rate, ObjectKind.VEHICLE, confidence, Lead.time_to_contact(rng, rate), self.box)
