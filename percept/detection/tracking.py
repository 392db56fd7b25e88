"""People tracked on the ground plane: each detection's feet (the bottom centre of its person box) projected onto
the road through the rig, a constant-velocity Kalman filter (filterpy) per person over (x, y, vx, vy) in the
vehicle frame (the velocity over the ground, turned with the vehicle) with the ego's own motion, its travel and its
turn, as the control input, greedy nearest-neighbour association inside a Mahalanobis gate, confirmation after
``confirm_hits`` hits, and coasting through misses and dropped frames.

Ground-contact range: a feet row v below the horizon lies at depth Z = fy h / (v - v_horizon) for a camera h
above the road, so a row error sigma_v gives sigma_Z = Z^2 sigma_v / (fy h): the measurement noise grows with Z^2.
References: Bar-Shalom, Li & Kirubarajan, "Estimation with Applications to Tracking and Navigation" (2001), the
white-noise-acceleration model (ch. 6) and gating (ch. 7).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from percept.sensors import StereoRig, iou

from .constrained import standing_box
from .ego_step import EgoStep
from .free_motion import FreeMotion, constant_velocity_filter

Box = tuple[float, float, float, float]
StereoDepth = Callable[[Box, float], "tuple[float, float] | None"]
"""(person box, its ground-contact depth [m]) -> (stereo depth, its standard deviation) [m] or None."""


@dataclass(frozen=True)
class TrackConfig:
    """Settings of the person tracker: confirmation, coasting, measurement noise, gates and the vehicle test."""

    confirm_hits: int = 3  # hits before a track is reported
    max_misses: int = 8  # frames a track coasts without a detection (it keeps acting on braking)
    report_misses: int = 2  # frames without a detection after which a track is no longer reported as seen
    accel_mps2: float = 0.7  # the people's white-noise acceleration [m/s²]
    row_sigma_frac: float = 0.05  # feet-row noise as a fraction of the person's height
    col_sigma_frac: float = 0.15  # column noise as a fraction of the person's height
    iou_gate: float = 0.3  # smallest overlap of a detection with a track's predicted box that pairs them
    gate_chi2: float = 9.21  # squared Mahalanobis gate on the ground (2 degrees of freedom, 99 %)
    sigma_v0_mps: float = 1.0  # a new track's speed uncertainty [m/s] (people walk at up to ~2 m/s)
    free_sigma_v0_mps: float = 30.0  # the same for the free motion, which assumes no person (a vehicle's speed) [m/s]
    # squared Mahalanobis distance beyond which a detection's noise is inflated in the free motion (``FreeMotion``; 2
    # degrees of freedom, 99.9 %): one window on another part of a vehicle, its feet 10 m nearer, must not pull the
    # free motion to a standstill in one frame
    free_gate_chi2: float = 13.8
    # a track whose free motion is faster than this by ``too_fast_sigmas`` of its standard deviation moves like a
    # vehicle (whose tail light and wheel can read as legs) and is no person on foot until its free motion is as
    # clearly slower [m/s]; people walk at up to 2.5 m/s, and a far person's first ranges (the feet's row quantised)
    # can read several times that for a few frames
    vehicle_min_mps: float = 8.0
    too_fast_sigmas: float = 2.5  # the margin of ``vehicle_min_mps``, in standard deviations of the free speed
    # a detection that must be verified (a lone window) is kept only when its stereo depth and its ground contact's
    # agree within this squared number of standard deviations (one degree of freedom)
    verify_chi2: float = 9.0


@dataclass(frozen=True)
class PersonTrack:
    """A tracked person. track_id; position_m: (x, y) of the feet in the vehicle frame [m]; velocity_mps: (vx, vy)
    over the ground [m/s] (the ego's own motion removed); sigma_vy_mps: standard deviation of vy; height_m: the
    person's estimated height; box_px: (u0, v0, u1, v1) the person box in the left image (predicted when not seen
    this frame); score: the last detection's score; hits; misses: frames since the last detection; confirmed;
    seen: confirmed and detected within the last ``report_misses`` frames (what the slot reports as seen);
    standing_m: (x, y) where the person would be had they stood still since their last detection [m] (the
    position then, moved by the ego's own motion only); stereo_hits: detections whose stereo depth agreed with
    their ground contact's (``TrackConfig.verify_chi2``); free_speed_mps, sigma_free_speed_mps: the speed over the
    ground [m/s] and its standard deviation as the detections alone tell it, without the prior that a person barely
    moves (``velocity_mps`` lags a vehicle's corner taken for a person by seconds; this one does not); too_fast:
    the free motion has been a vehicle's (``TrackConfig.vehicle_min_mps``) and has not since been clearly slower:
    whatever it is, no person on foot (held, since one detection on another part of the vehicle can pull the free
    motion back for a frame; released, since a far person's first ranges can run ahead of them)."""

    track_id: int
    position_m: tuple[float, float]
    velocity_mps: tuple[float, float]
    sigma_vy_mps: float
    height_m: float
    box_px: Box
    score: float
    hits: int
    misses: int
    confirmed: bool
    seen: bool
    standing_m: tuple[float, float]
    stereo_hits: int
    free_speed_mps: float
    sigma_free_speed_mps: float
    too_fast: bool


class _Track:
    """One person's filters (the person's and the free motion's) and counts."""

    def __init__(self, tid: int, xy: np.ndarray, r: np.ndarray, height_m: float, box: Box, score: float,
                 stereo_ok: bool, cfg: TrackConfig):
        # two filters on the same detections: the person's (a person barely moves: a tight prior on the speed) and
        # the free motion's (anything from standing to a vehicle's speed), which tells whether it is a person at all
        self.kf = constant_velocity_filter(xy, r, cfg.sigma_v0_mps)
        self.free = FreeMotion(xy, r, cfg.free_sigma_v0_mps, cfg.free_gate_chi2, cfg.vehicle_min_mps,
                               cfg.too_fast_sigmas)
        self.id, self.height_m, self.box, self.score = tid, height_m, box, score
        self.hits, self.misses, self.stereo_hits, self.cfg = 1, 0, int(stereo_ok), cfg
        self.predicted = box  # the person box predicted for the current frame
        self.standing = xy.copy()  # the last detection's position, moved by the ego's motion since

    def predict(self, step: EgoStep) -> None:
        self.kf.predict(u=step.travel, B=step.b, F=step.f, Q=step.q)
        self.free.predict(step.f, step.q, step.b, step.travel)
        self.standing = step.rt @ (self.standing - step.travel)

    def update(self, xy: np.ndarray, r: np.ndarray, height_m: float, box: Box, score: float, stereo_ok: bool) -> None:
        self.kf.update(xy, R=r)
        self.free.update(xy, r)
        self.standing = self.kf.x[:2].copy()
        # the height: a running mean of the per-frame estimates
        self.height_m += (height_m - self.height_m) / min(self.hits + 1, 10)
        self.box, self.score = box, score
        self.hits += 1
        self.stereo_hits += int(stereo_ok)
        self.misses = 0


class PersonTracker:
    """Detections (person boxes in the left image) -> tracked people on the ground plane."""

    def __init__(self, rig: StereoRig, dt_s: float, cfg: TrackConfig = TrackConfig()):
        self.rig, self.dt_s, self.cfg = rig, dt_s, cfg
        self.cam_x = float(rig.camera_position()[0])
        self.tracks: list[_Track] = []
        self._next_id = 1

    def reset(self) -> None:
        self.tracks, self._next_id = [], 1

    def measure(self, box: Box, stereo: StereoDepth | None = None,
                verify: bool = False) -> tuple[np.ndarray, np.ndarray, float, bool] | None:
        """A person box -> feet (x, y) [m], its 2x2 covariance, the person's height [m] and whether the stereo depth
        agreed with the ground contact's (``TrackConfig.verify_chi2``); None above the horizon or nearer than the
        camera. ``stereo(box, z_ground_m)``, when given, returns the box's stereo depth and its standard deviation
        [m] (or None), fused with the ground contact's by their inverse variances. ``verify``: None also unless the
        stereo depth agrees: a person stands where their feet touch the road, a pattern on the road or the scenery
        behind it does not."""
        cam, h_cam = self.rig.camera, self.rig.mount_height_m
        u0, v0, u1, v1 = box
        h_px = v1 - v0
        if v1 - self.rig.horizon_row < 1.0:
            return None
        xy = self.rig.image_to_ground(np.array([[(u0 + u1) / 2, v1]]))[0]
        z = xy[0] - self.cam_x
        if z <= 0.5:
            return None
        # sigma_Z = Z^2 sigma_v / (fy h)
        var_z = max(z * z * self.cfg.row_sigma_frac * h_px / (cam.fy * h_cam), 0.1) ** 2
        zs = stereo(box, z) if stereo is not None else None
        # (z_s - z_g)^2 <= chi2 (s_g^2 + s_s^2)
        agreed = zs is not None and bool((zs[0] - z) ** 2 <= self.cfg.verify_chi2 * (var_z + zs[1] ** 2))
        if verify and not agreed:
            return None
        cy = float(self.rig.camera_position()[1])
        if zs is not None:
            z_s, s_s = zs
            # inverse-variance fusion: z = (z_g / s_g^2 + z_s / s_s^2) / (1 / s_g^2 + 1 / s_s^2)
            w_g, w_s = 1.0 / var_z, 1.0 / (s_s * s_s)
            z_new = (z * w_g + z_s * w_s) / (w_g + w_s)
            var_z = 1.0 / (w_g + w_s)
            # the same ray from the camera, at the fused depth
            xy = np.array([self.cam_x + z_new, cy + (xy[1] - cy) * z_new / z])
            z = z_new
        # sigma_Y = Z sigma_u / fx: the bearing's own noise, across the ray
        s_y = max(z * self.cfg.col_sigma_frac * h_px / cam.fx, 0.05)
        # the depth's noise moves the feet along their ray, y - cy = t Z with t = (y - cy) / Z, so x and y err
        # together: R = var_Z [[1, t], [t, t^2]] + diag(0, s_y^2); an off-axis person's range settling is then not
        # taken for a sideways walk
        t = (xy[1] - cy) / z
        r = var_z * np.array([[1.0, t], [t, t * t]]) + np.diag([0.0, s_y * s_y])
        # H = h_px Z / fy
        return xy, r, float(h_px * z / cam.fy), agreed

    def predicted_boxes(self, tracks: list[_Track]) -> list[Box]:
        """The person box each track predicts in the left image: its feet projected, its height above them (every
        track's points projected at once: the same values as one track at a time)."""
        if not tracks:
            return []
        pts = np.array([[t.kf.x[0], t.kf.x[1], z] for t in tracks for z in (0.0, t.height_m)])
        uv = self.rig.project_vehicle_points(pts)[0].tolist()
        return [standing_box(feet[0], feet[1], max(feet[1] - head[1], 1.0)) for feet, head in zip(uv[::2], uv[1::2])]

    def predict(self, ego_speed_mps: float, yaw_rate_rps: float = 0.0) -> list[Box]:
        """Advance every track one frame while the ego drives ``ego_speed_mps`` and turns at ``yaw_rate_rps``
        (positive to the left); the predicted person boxes (for the search's regions of interest)."""
        step = EgoStep.of(self.dt_s, ego_speed_mps, yaw_rate_rps, self.cfg.accel_mps2) if self.tracks else None
        for t in self.tracks:
            t.predict(step)
        boxes = self.predicted_boxes(self.tracks)
        # a track that has walked (or been driven) out of the image, or behind the camera, has gone
        w = self.rig.camera.width
        keep = [i for i, (t, b) in enumerate(zip(self.tracks, boxes)) if t.kf.x[0] - self.cam_x > 0.5
                and b[2] > 0 and b[0] < w]
        self.tracks = [self.tracks[i] for i in keep]
        for t, b in zip(self.tracks, [boxes[i] for i in keep]):
            t.predicted = b
        return [boxes[i] for i in keep]

    def update(self, boxes: list[Box], scores: list[float], seen: bool = True, stereo: StereoDepth | None = None,
               verify: list[bool] | None = None) -> list[PersonTrack]:
        """Associate this frame's person boxes (measured with ``stereo`` when given, see ``measure``; those flagged
        in ``verify`` kept only when the stereo depth agrees) with the predicted tracks; ``seen`` False (a dropped
        frame): no detections and no misses counted."""
        flags = verify if verify is not None else [False] * len(boxes)
        meas = [(m, b, s) for b, s, f in zip(boxes, scores, flags) if (m := self.measure(b, stereo, f)) is not None]
        pairs = self._associate(meas)
        used = set()
        for ti, mi in pairs:
            (xy, r, hm, ok), b, s = meas[mi]
            self.tracks[ti].update(xy, r, hm, b, s, ok)
            used.add(mi)
        matched = {ti for ti, _ in pairs}
        for i, t in enumerate(self.tracks):
            if seen and i not in matched:
                t.misses += 1
        self.tracks = [t for t in self.tracks if t.misses <= self.cfg.max_misses]
        for mi, ((xy, r, hm, ok), b, s) in enumerate(meas):
            # a detection on a person already tracked (a second window on them) starts no track of its own
            taken = [t.box if t.misses == 0 else t.predicted for t in self.tracks]
            if mi not in used and not any(iou(b, other) > 0.3 for other in taken):
                self.tracks.append(_Track(self._next_id, xy, r, hm, b, s, ok, self.cfg))
                self._next_id += 1
        return [self._public(t) for t in self.tracks]

    def _associate(self, meas: list) -> list[tuple[int, int]]:
        """Greedy pairs (track, measurement): first by the overlap of the detection with the track's predicted box
        (IoU >= ``iou_gate``: robust to the far field's range noise), then by squared Mahalanobis distance on the
        ground inside the gate."""
        cands = []
        if not meas or not self.tracks:
            return []
        for ti, t in enumerate(self.tracks):
            hx = t.kf.H @ t.kf.x
            hp = t.kf.H @ t.kf.P @ t.kf.H.T
            for mi, ((xy, r, _, _), box, _) in enumerate(meas):
                overlap = iou(box, t.predicted)
                d = xy - hx
                # d^2 = (z - H x)^T S^-1 (z - H x), S = H P H^T + R
                d2 = float(d @ np.linalg.solve(hp + r, d))
                if overlap >= self.cfg.iou_gate:
                    cands.append((0, -overlap, ti, mi))
                elif d2 <= self.cfg.gate_chi2:
                    cands.append((1, d2, ti, mi))
        pairs, tu, mu = [], set(), set()
        for _, _, ti, mi in sorted(cands):
            if ti not in tu and mi not in mu:
                pairs.append((ti, mi))
                tu.add(ti)
                mu.add(mi)
        return pairs

    def _public(self, t: _Track) -> PersonTrack:
        """The record reported of a track, its box clipped to the image."""
        x = t.kf.x
        box = t.box if t.misses == 0 else t.predicted
        w, h = self.rig.camera.width, self.rig.camera.height
        # boxes are of what the image shows: clipped to it
        box = (min(max(box[0], 0.0), w), min(max(box[1], 0.0), h), min(max(box[2], 0.0), w), min(max(box[3], 0.0), h))
        return PersonTrack(t.id, (float(x[0]), float(x[1])), (float(x[2]), float(x[3])),
                           float(np.sqrt(max(t.kf.P[3, 3], 0.0))), float(t.height_m),
                           tuple(float(c) for c in box), float(t.score), t.hits, t.misses,
                           t.hits >= self.cfg.confirm_hits,
                           t.hits >= self.cfg.confirm_hits and t.misses <= self.cfg.report_misses,
                           (float(t.standing[0]), float(t.standing[1])), t.stereo_hits, *t.free.speed, t.free.too_fast)
