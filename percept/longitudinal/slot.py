"""The vision longitudinal slot: the stereo pair and the ego path in, the lead out.

Each frame: the nearest obstacle standing in the path (``obstacles``) and three measurements of it: its range
from stereo (subpixel disparity over the lower part that faces the ego, ``refine``: Z = f b / d, noise
sigma_Z = Z^2 sigma_d / (f b)); its range from where its tyres meet the road (``contact``); its range rate from
the expansion of its image (``flow``: dZ/dt = -Z (s - 1) / dt). A Kalman filter (filterpy) over range, range rate
and range acceleration (constant acceleration, white jerk noise) takes each with its own noise, each gated. Two
stereo ranges in a row beyond the gate are a new lead when the obstacle's box moved (a cut-in, the lead changing
lanes), else the same lead manoeuvring (braking hard): the filter's uncertainty is opened up. A track is confirmed
by hits on an obstacle that stays in place in the image, reported once confirmed, kept through short misses,
dropped frames and frames whose range does not refine, with a confidence that falls while it is only predicted.
Nothing in the ego's path drives backwards towards it, so the range rate is held at or above minus the ego's wheel
speed (a state constraint; none on a frame whose wheel-speed sample is bad).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from percept.sensors import EgoMotionGate, EgoPath, Frame, Lead, ObjectKind, StereoRig, iou

from .contact import Contact, ContactConfig, ContactRange
from .flow import Expansion, ExpansionTracker, FlowConfig
from .obstacles import Obstacle, ObstacleConfig, ObstacleFinder
from .range_filter import RANGE, RATE, RangeFilter
from .refine import PatchAligner, Refined, surface_mask, warm_up_refinement


OUTLINE_COLS = 2
"""Columns at each side of an obstacle's band left out of the second disparity refinement: half the 5x5 block."""
MAX_OUTLINE_SHIFT_PX = 0.4
"""How far leaving the outline out may move the refined disparity [px]; further is a wrong minimum."""


@dataclass(frozen=True)
class LeadConfig:
    """Settings of the vision longitudinal slot: the stereo refinement, the range filter, the track's life and the
    cues' own settings."""

    face_m: tuple[float, float] = (0.4, 0.9)  # heights above the road of the band whose disparity is refined [m]
    # floor on the disparity noise [px]: the refinement's own standard error is often far smaller, and the floor
    # covers what it does not model (slanted faces, pixels at the outline)
    sigma_d_px: float = 0.05
    column_fill: float = 0.3  # a column of the band is the obstacle's when this fraction of it matches its disparity
    huber: float = 6.0  # the refinement's Huber threshold [grey levels]
    # white jerk noise of the range [m/s³] (the filter is constant-acceleration, so that a lead braking hard is
    # followed without lag)
    jerk_sigma_mps3: float = 8.0
    gate_sigma: float = 5.0  # innovations beyond this many sigma are outliers
    # two outliers in a row are a new lead when its box overlaps the last one by less than this (IoU), else the same
    # lead manoeuvring
    same_object_iou: float = 0.3
    manoeuvre_rate_mps: float = 5.0  # a manoeuvre grows the filter's rate variance by this squared [m/s]
    manoeuvre_accel_mps2: float = 6.0  # and its acceleration variance by this squared [m/s²]
    confirm: int = 3  # hits before a track is reported
    hold_s: float = 0.6  # how long a track is predicted without measurements [s]
    # how fast a lead may come towards the ego beyond the ego's own speed [m/s] (estimation noise: leads do not
    # reverse on a road)
    reverse_mps: float = 1.0
    obstacles: ObstacleConfig = ObstacleConfig()  # the obstacle finder's settings
    contact: ContactConfig = ContactConfig()  # the ground-contact range's settings
    flow: FlowConfig = FlowConfig()  # the expansion measurement's settings


@dataclass(frozen=True)
class LeadDebug:
    """obstacle: this frame's nearest standing group (None if none); refined: its subpixel disparity; measured_m:
    the stereo range [m] (None without one); contact: the ground-contact range; expansion: the image expansion
    (flow); used: which of "stereo", "contact", "flow" updated the filter; state: (range, range rate) after the
    update; hits, misses: the track's counts."""

    obstacle: Obstacle | None
    refined: Refined | None
    measured_m: float | None
    contact: Contact | None
    expansion: Expansion | None
    used: tuple[str, ...]
    state: tuple[float, float] | None
    hits: int
    misses: int


class LongitudinalSlot:
    """Slot interface: ``reset()``, ``step(frame, upstream) -> (Lead | None, LeadDebug)``; reads the ego path
    (``upstream[EgoPath]``, a straight corridor without it)."""

    def __init__(self, rig: StereoRig, dt_s: float, cfg: LeadConfig = LeadConfig()):
        self.rig, self.dt, self.cfg = rig, dt_s, cfg
        self.finder = ObstacleFinder(rig, cfg.obstacles)
        self.contact = ContactRange(rig, cfg.contact)
        self.flow = ExpansionTracker(cfg.flow)
        self.fb = rig.camera.fx * rig.baseline_m
        self.motion = EgoMotionGate()
        warm_up_refinement()
        self.reset()

    def reset(self) -> None:
        """A new run: no track, and the road plane back to the rig's."""
        self.finder.reset()
        self.motion.reset()
        self._rate_floor_mps = -np.inf
        self._drop_track()

    def _drop_track(self) -> None:
        self.track: RangeFilter | None = None
        self.hits = self.misses = self.outliers = 0
        self.box: tuple | None = None
        self.flow.reset()

    def step(self, frame: Frame, upstream: dict) -> tuple[Lead | None, LeadDebug]:
        """One frame: the confirmed lead in the path (None without one) and what each cue measured."""
        motion = self.motion.update(frame)
        path = upstream.get(EgoPath) or EgoPath.straight(motion.speed_mps)
        # nothing in the path comes towards the ego faster than it drives: range rate >= -(v_ego + reverse_mps)
        self._rate_floor_mps = -(motion.speed_mps + self.cfg.reverse_mps) if motion.speed_ok else -np.inf
        self.predict()
        ob = ref = z = contact = expansion = None
        used: tuple[str, ...] = ()
        if not frame.dropped:
            left, right = frame.left_gray, frame.right_gray
            ob, _ = self.finder.find(left, right, path)
            if ob is not None:
                ref = self.refine(left, right, ob)
                z = self.fb / ref.disparity_px if ref is not None and ref.disparity_px > 0.5 else ob.range_m
                contact = self.contact.measure(left, ob.box_px, z)
                used = self.update(z, ref, ob, contact)
                expansion = self.flow.measure(left, ob.box_px, frame.timestamp_s) if used else None
                if expansion is not None and self._update_rate(expansion):
                    used += ("flow",)
        if used and ref is not None:
            self.misses = 0
        else:
            # a frame without a refined stereo range is a miss for the track's life, though its unrefined range and
            # the ground contact still update the filter: a far box that never refines (the road's end at night,
            # where contact edges jump between rows metres apart) is not followed for longer than hold_s
            self._miss()
        state = None if self.track is None else (self.track.range_m, self.track.rate_mps)
        return self._lead(), LeadDebug(ob, ref, z, contact, expansion, used, state, self.hits, self.misses)

    def refine(self, left: np.ndarray, right: np.ndarray, ob: Obstacle) -> Refined | None:
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
        # the obstacle's own columns: where much of the band matches (stray matches on the road beside it, e.g. on
        # a slanted lane line, would pull the estimate)
        # (the fraction as np.mean takes it: the count over the rows, in float64)
        cols = np.flatnonzero(m.sum(axis=0) / m.shape[0] >= self.cfg.column_fill)
        if len(cols) == 0 or cols[-1] - cols[0] < 2:
            return None
        m[:, :cols[0]] = False
        m[:, cols[-1] + 1:] = False
        if m.sum() < 12:
            return None
        aligner = PatchAligner(L, R, box)
        full = aligner.refine(m, d0, huber=self.cfg.huber)
        if full is None:
            return None
        # then without their outline: a 5x5 block straddling it matches at the obstacle's disparity with half of it
        # on what lies behind (foreground fattening), and the outline's strong gradients pull the fit. The inner
        # pixels alone, started where all of them converged, correct that; a far obstacle's few inner pixels can
        # also lock onto a wrong minimum further away, and then the fit with the outline stands
        k = OUTLINE_COLS
        inner = m.copy()
        inner[:, :cols[0] + k] = False
        inner[:, cols[-1] + 1 - k:] = False
        if inner.sum() < 12:
            return full
        ref = aligner.refine(inner, full.disparity_px, huber=self.cfg.huber)
        if ref is None or abs(ref.disparity_px - full.disparity_px) > MAX_OUTLINE_SHIFT_PX:
            return full
        return ref

    def predict(self) -> None:
        """The track one frame ahead, then this frame's floor on its range rate."""
        if self.track is not None:
            self.track.predict(self._rate_floor_mps)

    def _new_track(self, z: float, sigma: float) -> None:
        self.track = RangeFilter(z, sigma, self.dt, self.cfg.jerk_sigma_mps3, self._rate_floor_mps)
        self.hits, self.misses, self.outliers = 1, 0, 0
        self.flow.reset()

    def _miss(self) -> None:
        self.misses += 1
        if self.track is not None and self.misses * self.dt > self.cfg.hold_s:
            self._drop_track()

    def _gated_update(self, value: float, sigma: float, i: int) -> bool:
        """One measurement ``value`` of state ``i`` with noise ``sigma``, unless it is beyond the gate; True if used."""
        return self.track.gated_update(value, sigma, i, self.cfg.gate_sigma)

    def update(self, z: float, ref: Refined | None, ob: Obstacle, contact: Contact | None) -> tuple[str, ...]:
        """The range measurements: stereo (which also starts and replaces tracks), then ground contact."""
        if ref is None and (self.track is None or self.hits < self.cfg.confirm):
            # a group whose disparity does not refine (no surface with a clear match: chance matches on the dark,
            # noisy background at the road's far end at night) neither starts nor confirms a track
            return ()
        sd = max(ref.sigma_px if ref is not None else 1.0, self.cfg.sigma_d_px)
        # stereo range noise: sigma_Z = Z^2 sigma_d / (f b), for an unrefined range at the track's range (at its
        # own, a chance match 60 m off a track at 12 m would pass the gate)
        at = z if ref is not None else self.track.range_m
        sigma = at * at * sd / self.fb
        if ref is None:
            # nor replaces one or passes for a lead manoeuvring: it only updates a confirmed track it agrees with
            if not self._gated_update(z, sigma, RANGE):
                return ()
            self.box, used = ob.box_px, ("stereo",)
        else:
            previous, self.box = self.box, ob.box_px
            overlap = 0.0 if self.track is None else iou(previous, ob.box_px)
            if self.track is None or (self.hits < self.cfg.confirm and overlap < self.cfg.same_object_iou):
                # a track is confirmed only by an obstacle that stays where it was in the image (rain streaks
                # and matches made by chance jump about)
                self._new_track(z, sigma)
                return ("stereo",)
            used, restarted = self._refined_update(z, sigma, overlap)
            if restarted:
                return used
        if contact is not None and self._gated_update(contact.range_m, contact.sigma_m, RANGE):
            used += ("contact",)
        if used:
            self.hits += 1
        return used

    def _refined_update(self, z: float, sigma: float, overlap: float) -> tuple[tuple[str, ...], bool]:
        """A refined stereo range of a track's obstacle (``overlap``: its box's IoU with the last one), gated: two
        outliers in a row are a new lead when the box moved, else the lead manoeuvring. (used cues, whether a new
        track was started)."""
        if self._gated_update(z, sigma, RANGE):
            self.outliers = 0
            return ("stereo",), False
        self.outliers += 1
        if self.outliers < 2:
            return (), False
        if overlap < self.cfg.same_object_iou:
            self._new_track(z, sigma)  # the lead changed (a cut-in, the lead leaving): follow the new one
            return ("stereo",), True
        # the same object, manoeuvring (braking hard): open the filter up and take the measurement
        self.track.manoeuvre(z, sigma, self.cfg.manoeuvre_rate_mps, self.cfg.manoeuvre_accel_mps2)
        self.outliers = 0
        return ("stereo",), False

    def _update_rate(self, e: Expansion) -> bool:
        """The range rate from the image's expansion at the current range: dZ/dt = -Z (s - 1) / dt."""
        z = self.track.range_m
        sigma = z * e.sigma / e.dt_s
        return self._gated_update(e.range_rate_mps(z), sigma, RATE)

    def _lead(self) -> Lead | None:
        """The confirmed track as a Lead, its confidence falling while it is only predicted."""
        if self.track is None or self.hits < self.cfg.confirm:
            return None
        rng, rate = self.track.range_m, self.track.rate_mps
        confidence = max(0.0, 1.0 - self.misses * self.dt / self.cfg.hold_s)
        # whatever stands in the path is followed like a vehicle; people are the pedestrian slot's to yield to
        return Lead(rng, rate, ObjectKind.VEHICLE, confidence, Lead.time_to_contact(rng, rate), self.box)
