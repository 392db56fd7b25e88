"""Neighbour tracks: one Kalman filter (filterpy) per vehicle over its along-lane position and speed and its lateral
position and speed, in the ego lane's coordinates, fed by both rigs' detections.

Constant velocity with white acceleration noise (Bar-Shalom, Li & Kirubarajan 2001, sec. 6.3.2). A track is
confirmed after ``confirm_hits`` detections, dropped after ``max_misses`` frames unseen where a rig could see it; in
the blind band beside the ego, which neither rig sees, it is kept by prediction (held inside the band, its position
uncertainty growing) until a rig takes it over as it comes out, so a lane is never reported free while a vehicle may
be beside the ego.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

import numpy as np
from filterpy.kalman import KalmanFilter

from .clusters import DEFAULT_LANE_WIDTH_M, Detection


@dataclass(frozen=True)
class TrackerConfig:
    """How tracks are made, kept and dropped."""

    accel_noise_mps2: float = 2.0  # along-lane white acceleration (1-sigma) [m/s^2]
    lateral_accel_noise_mps2: float = 0.8  # lateral white acceleration (1-sigma) [m/s^2]
    manoeuvre_accel_noise_mps2: float = 4.0  # ... while the track manoeuvres sideways (a car pulling out) [m/s^2]
    manoeuvre_sigmas: float = 1.0  # a lateral innovation beyond this many sigmas ...
    manoeuvre_frames: int = 2  # ... of one sign this many detections in a row starts a manoeuvre, which lasts
    # until an innovation of that sign falls under it [-]
    lateral_sigma_m: float = 0.12  # a detection's lateral position noise near by (1-sigma), added in quadrature to
    # the detection's own range-dependent sigma_lat_m [m]
    outlier_sigmas: float = 3.0  # a lateral innovation beyond this many sigmas is down-weighted to this size [-]
    gate_x_m: float = 3.0  # association gate along the lane, plus gate_x_rel of the range [m]
    gate_x_rel: float = 0.08  # ... [-]
    gate_l_m: float = 1.4  # association gate across it [m]
    confirm_hits: int = 3  # detections that confirm a track
    max_misses: int = 6  # frames unseen (where a rig looks) that drop a track
    blind_behind_m: float = -14.0  # the blind band beside the ego, where a rig sees too little of a car to find it:
    # centres from here ...
    blind_ahead_m: float = 12.0  # ... to here, along the lane, in the lanes beside [m]
    fringe_m: float = 10.0  # beyond each end of the band, where a rig sees a car beside only in part (cut off by the
    # image's edge): an established track there heading for the band coasts unseen instead of counting misses [m]
    max_blind_s: float = 60.0  # longest a track is kept by prediction alone in the blind band [s]
    min_settled: int = 10  # detections in a row in one lane, since the track was laterally still in it, that make it
    # a settled neighbour there (a car still moving over from the lane beyond is not) [-]
    still_mps: float = 0.3  # a track is laterally still once its lateral speed is below this [m/s] ...
    still_frames: int = 3  # ... on this many detections in a row since it was confirmed (its filter starts at rest) [-]
    blind_spread_mps: float = 2.0  # how fast the along-lane uncertainty of a track in the band grows [m/s]
    recent_s: float = 1.0  # the window over which a track's detections are counted (Track.seen) [s]


@dataclass
class Track:
    """One vehicle's filter and bookkeeping."""

    track_id: int
    kf: KalmanFilter
    hits: int = 1
    misses: int = 0
    blind_s: float = 0.0  # how long it has been held in the blind band (0: not held) [s]
    takeover: int = 0  # detections in a row since a rig saw it again while it was held
    camera: str | None = None
    box_px: tuple | None = None
    confirmed: bool = False
    cut_off: bool = False  # its last detection was cut off by the image's edge
    lane: int | None = None  # the lane its centre was in at its last detection (-1, 0, +1 ...)
    settled: int = 0  # detections in a row in that lane since it was laterally still there
    still: bool = False  # it has been laterally still in that lane
    calm: int = 0  # detections in a row with its lateral speed under TrackerConfig.still_mps
    warning: bool = False  # flagged as cutting in at the last report
    veer: int = 0  # signed count of the lateral innovations in a row beyond TrackerConfig.manoeuvre_sigmas, all of
    # one sign (+ left) [-]
    seen_bits: int = 1  # one bit a frame, the newest lowest: whether a rig found it (the last TrackerConfig.recent_s)

    @property
    def x(self) -> float:
        return float(self.kf.x[0, 0])

    @property
    def lat(self) -> float:
        return float(self.kf.x[2, 0])

    @property
    def seen(self) -> int:
        """On how many of the last ``TrackerConfig.recent_s`` of frames a rig found it."""
        return self.seen_bits.bit_count()


class NeighbourTracker:
    """Tracks of the vehicles around the ego from per-rig detections."""

    def __init__(self, dt_s: float, cfg: TrackerConfig = TrackerConfig()):
        self.dt, self.cfg = dt_s, cfg
        self.tracks: list[Track] = []
        self._next_id = 1
        self.width = DEFAULT_LANE_WIDTH_M  # the lane width of the last frame [m]
        # white acceleration: Q = q^2 [[dt^4/4, dt^3/2], [dt^3/2, dt^2]] per axis
        self._block = np.array([[dt_s ** 4 / 4, dt_s ** 3 / 2], [dt_s ** 3 / 2, dt_s ** 2]])

    def reset(self) -> None:
        self.tracks.clear()
        self._next_id = 1

    def _new_filter(self, det: Detection) -> KalmanFilter:
        dt, c = self.dt, self.cfg
        kf = KalmanFilter(dim_x=4, dim_z=2)
        # state (x, x', l, l'): x_k+1 = x_k + dt x'_k, l_k+1 = l_k + dt l'_k
        kf.F = np.array([[1, dt, 0, 0], [0, 1, 0, 0], [0, 0, 1, dt], [0, 0, 0, 1]], float)
        kf.H = np.array([[1, 0, 0, 0], [0, 0, 1, 0]], float)
        kf.Q = np.zeros((4, 4))
        kf.Q[:2, :2] = self._block * c.accel_noise_mps2 ** 2
        kf.Q[2:, 2:] = self._block * c.lateral_accel_noise_mps2 ** 2
        kf.x = np.array([[det.x_m], [0.0], [det.lat_m], [0.0]])
        sigma_l2 = c.lateral_sigma_m ** 2 + det.sigma_lat_m ** 2
        kf.P = np.diag([max(det.sigma_x_m, 0.3) ** 2, 6.0 ** 2, sigma_l2, 1.0 ** 2])
        return kf

    @property
    def recent_frames(self) -> int:
        """How many frames ``TrackerConfig.recent_s`` spans (``Track.seen`` counts over them)."""
        return max(round(self.cfg.recent_s / self.dt), 1)

    def shift_lanes(self, moved_m: float) -> None:
        """The lane coordinates moved ``moved_m`` [m] to the left (the ego changed lanes): each track's lateral
        position is taken from the new centre line, l' = l - moved, and its lane follows."""
        for t in self.tracks:
            t.kf.x[2, 0] -= moved_m
            t.lane = None if t.lane is None else int(round(t.lat / self.width))

    def in_blind_band(self, x_m: float, lat_m: float, width_m: float) -> bool:
        """Whether a centre at (x_m, lat_m) lies where neither rig sees: beside the ego in a lane beside it."""
        return self.cfg.blind_behind_m <= x_m <= self.cfg.blind_ahead_m and abs(lat_m) >= 0.5 * width_m

    def step(self, detections: dict[str, list[Detection]], width_m: float) -> None:
        """One frame: predict every track, associate each rig's detections (``detections``: rig name -> its
        detections), make new tracks, keep the blind band's tracks and drop the lost ones."""
        window = (1 << self.recent_frames) - 1
        for t in self.tracks:
            q = self.cfg.manoeuvre_accel_noise_mps2 if self.manoeuvring(t) else self.cfg.lateral_accel_noise_mps2
            t.kf.Q[2:, 2:] = self._block * q ** 2
            t.kf.predict()
            t.camera, t.box_px = None, None
            t.seen_bits = (t.seen_bits << 1) & window
        self.width = width_m
        for rig, dets in detections.items():
            self._associate(rig, dets)
        self._merge()
        self._keep_or_drop(width_m)

    def _merge(self) -> None:
        """Two tracks in one lane, each within the other's association gate, are one car tracked twice (far away its
        face breaks into groups that may each start a track): the one with more detections stays (a young one
        measured this frame beside an established one unseen for a frame is the duplicate). Tracks held in the blind
        band are left to the hand-over."""
        w, gone = self.width, set()
        for a, b in combinations([t for t in self.tracks if t.blind_s <= 0], 2):
            if id(a) in gone or id(b) in gone or round(a.lat / w) != round(b.lat / w):
                continue
            if abs(a.x - b.x) <= self._gate_x(min(abs(a.x), abs(b.x))) and abs(a.lat - b.lat) <= self.cfg.gate_l_m:
                gone.add(id(b) if a.hits >= b.hits else id(a))  # the older-found stays on a tie
        self.tracks = [t for t in self.tracks if id(t) not in gone]

    def _gate_x(self, x_m: float) -> float:
        """The association gate along the lane for a track at ``x_m`` [m]: gate_x_m + gate_x_rel |x| [m]."""
        return self.cfg.gate_x_m + self.cfg.gate_x_rel * abs(x_m)

    def _associate(self, rig: str, dets: list[Detection]) -> None:
        c, pairs = self.cfg, []
        for i, t in enumerate(self.tracks):
            gate_t = self._gate_x(t.x)
            for j, d in enumerate(dets):
                # the gate widens with the detection's own along-lane uncertainty (a face cut off by the image's edge)
                gate_x = gate_t + 2 * d.sigma_x_m
                dx, dl = abs(d.x_m - t.x), abs(d.lat_m - t.lat)
                if dx <= gate_x and dl <= c.gate_l_m and self._may_take_over(t, d):
                    pairs.append((dx / gate_x + dl / c.gate_l_m, i, j))
        used_t, used_d = set(), set()
        for _, i, j in sorted(pairs):
            if i in used_t or j in used_d:
                continue
            used_t.add(i)
            used_d.add(j)
            t, d = self.tracks[i], dets[j]
            R = self._noise(t, d)
            self._count_veer(t, d.lat_m - t.lat, float(t.kf.P[2, 2]) + R[1, 1])
            t.kf.update(np.array([[d.x_m], [d.lat_m]]), R=R)
            t.hits, t.misses = t.hits + 1, 0
            t.seen_bits |= 1
            # a held track leaves the band once a rig has seen it confirm_hits times in a row: a lone detection of
            # something else does not carry it off (the next unseen frame puts it back in the band)
            t.takeover = t.takeover + 1 if t.blind_s > 0 else 0
            if t.takeover >= c.confirm_hits:
                t.blind_s, t.takeover = 0.0, 0
            t.camera, t.box_px, t.cut_off = rig, d.box_px, d.cut_off
            # its lane: round(l / w)
            lane = int(round(t.lat / self.width))
            t.calm = t.calm + 1 if t.hits >= c.confirm_hits and abs(float(t.kf.x[3, 0])) < c.still_mps else 0
            t.still = lane == t.lane and t.still or t.calm >= c.still_frames
            t.settled = t.settled + 1 if lane == t.lane and t.still else int(t.still)
            t.lane = lane
            t.confirmed = t.confirmed or t.hits >= c.confirm_hits
        # a detection left over inside the gate of a track this rig measured this frame is another part of that car
        # (far away a car's face breaks into several groups): it makes no track of its own
        parts = {j for _, i, j in pairs if i in used_t}
        for j, d in enumerate(dets):
            if j not in used_d and j not in parts:
                self.tracks.append(Track(self._next_id, self._new_filter(d), camera=rig, box_px=d.box_px))
                self._next_id += 1

    def manoeuvring(self, t: Track) -> bool:
        """Whether a track's lateral innovations say it moves sideways faster than its filter follows: then its
        lateral process noise is ``manoeuvre_accel_noise_mps2`` (Bar-Shalom, Li & Kirubarajan 2001, sec. 11.2: a
        manoeuvre detected from the innovations switches the noise level)."""
        return abs(t.veer) >= self.cfg.manoeuvre_frames

    def _count_veer(self, t: Track, nu_m: float, s_m2: float) -> None:
        """Count a lateral innovation ``nu_m`` [m] of variance ``s_m2`` [m^2] into ``Track.veer``: one beyond
        ``manoeuvre_sigmas`` of the sign of the run so far extends it, of the other sign starts a new run, and a
        small one ends it (a single jump of the face, which the outlier weighting damps, is a run of one)."""
        big = abs(nu_m) > self.cfg.manoeuvre_sigmas * np.sqrt(s_m2)
        sign = 1 if nu_m > 0 else -1
        t.veer = (t.veer + sign if t.veer * sign > 0 else sign) if big else 0

    def _may_take_over(self, t: Track, d: Detection) -> bool:
        """Whether detection ``d`` may update track ``t``: any may, but a track held in the blind band is taken over
        only by a car coming out of it, which a rig first sees at its image's edge (``cut_off``) or near the band's
        ends (within ``gate_x_m``), not by another car farther along the lane beside."""
        c = self.cfg
        if t.blind_s <= 0 or d.cut_off:
            return True
        return c.blind_behind_m - c.gate_x_m <= d.x_m <= c.blind_ahead_m + c.gate_x_m

    def _noise(self, t: Track, d: Detection) -> np.ndarray:
        """The measurement noise R of detection ``d`` for track ``t``: its along-lane sigma and its lateral one, the
        latter widened so that an innovation beyond ``outlier_sigmas`` counts as that many sigmas (Huber's weighting):
        a face that briefly takes in a car's side, or loses a lit part of its rear, jumps sideways by a metre."""
        c = self.cfg
        # sigma_l^2 = sigma_0^2 + sigma_d^2; innovation variance S_l = P_ll + sigma_l^2
        var_l = c.lateral_sigma_m ** 2 + d.sigma_lat_m ** 2
        s_l = float(t.kf.P[2, 2]) + var_l
        nu = abs(d.lat_m - t.lat)
        k = c.outlier_sigmas
        if nu > k * np.sqrt(s_l):
            # widen R_l until nu = k sqrt(P_ll + R_l)
            var_l = max(var_l, (nu / k) ** 2 - float(t.kf.P[2, 2]))
        return np.diag([max(d.sigma_x_m, 0.05) ** 2, var_l])

    def _hold_in_band(self, t: Track) -> None:
        """One frame of a track held in the blind band: nothing says it moves sideways, so it keeps its lateral place;
        if its prediction reaches the band's edge with no rig seeing it come out, it has matched the ego's speed
        somewhere in the band: it stops there, anywhere in the band as far as its uncertainty goes."""
        c = self.cfg
        t.kf.x[3, 0] = 0.0
        t.takeover = 0
        held = float(np.clip(t.x, c.blind_behind_m, c.blind_ahead_m))
        if held != t.x:
            t.kf.x[0, 0], t.kf.x[1, 0] = held, 0.0
            t.kf.P[0, 0] = max(t.kf.P[0, 0], ((c.blind_ahead_m - c.blind_behind_m) / 2) ** 2)
        t.blind_s += self.dt

    def _heading_for_band(self, t: Track) -> bool:
        """Whether a track lies in the band's fringe (``_in_fringe``) and moves towards the band."""
        # towards the band: x' < 0 ahead of it, x' > 0 behind it
        return self._in_fringe(t) and float(t.kf.x[1, 0]) * t.x < 0

    def sigma_x(self, t: Track) -> float:
        """A track's along-lane 1-sigma [m]: its filter's, widened at ``blind_spread_mps`` for as long as it has been
        held in the blind band (a car there may change its speed unseen)."""
        return float(np.sqrt(max(t.kf.P[0, 0], 0.0))) + self.cfg.blind_spread_mps * t.blind_s

    def _in_fringe(self, t: Track) -> bool:
        """Whether a track lies within ``fringe_m`` of the blind band's ends, outside it."""
        c = self.cfg
        return (c.blind_ahead_m < t.x <= c.blind_ahead_m + c.fringe_m
                or c.blind_behind_m - c.fringe_m <= t.x < c.blind_behind_m)

    def _keep_or_drop(self, width_m: float) -> None:
        """Unseen tracks: a confirmed one in (or come out of) the blind band is held in the band by prediction until a
        rig takes it over; one heading for the band from its fringe, established or last seen cut off by the image's
        edge, coasts; one last seen cut off in the fringe and not heading for the band (its speed read from faces that
        are only in part in view) is held too (a car at the edge that vanishes has gone on into the band); any other
        counts a miss, and too many drop it."""
        c = self.cfg
        kept = []
        for t in self.tracks:
            if t.camera is None:
                beside = t.confirmed and abs(t.lat) >= 0.5 * width_m
                heading = self._heading_for_band(t)
                coasts = beside and (t.hits >= c.min_settled or t.cut_off) and heading
                into = self.in_blind_band(t.x, t.lat, width_m) or t.blind_s > 0 or (
                    t.cut_off and self._in_fringe(t) and not heading)
                if beside and into and t.blind_s < c.max_blind_s:
                    self._hold_in_band(t)
                elif not coasts:
                    t.misses += 1
            if t.misses <= (c.max_misses if t.confirmed else 1):
                kept.append(t)
        self.tracks = kept
