"""Neighbour tracks: one Kalman filter (filterpy) per vehicle over its along-lane position and speed and its lateral
position and speed, in the ego lane's coordinates, fed by both rigs' detections.

Constant velocity with white acceleration noise (Bar-Shalom, Li & Kirubarajan 2001, sec. 6.3.2). A track is
confirmed after ``confirm_hits`` detections that are no slivers (too narrow for a car's face at their range), dropped
after ``max_misses`` frames unseen where a rig could see it; in the blind band beside the ego, which neither rig sees,
it is kept by prediction (held inside the band, its position uncertainty growing) until a rig takes it over as it
comes out, so a lane is never reported free while a vehicle may be beside the ego; a car in the ego lane too near for
the front rig to find is held the same way for a while.
"""

from __future__ import annotations

from copy import deepcopy
from itertools import combinations

import numpy as np
from filterpy.kalman import KalmanFilter

from percept.sensors import EGO_LENGTH_M

from .clusters import DEFAULT_LANE_WIDTH_M, VEHICLE_LENGTH_M, Detection
from .track import Track, TrackerConfig


class NeighbourTracker:
    """Tracks of the vehicles around the ego from per-rig detections."""

    def __init__(self, dt_s: float, cfg: TrackerConfig = TrackerConfig()):
        self.dt, self.cfg = dt_s, cfg
        self.tracks: list[Track] = []
        self._next_id = 1
        self.width = DEFAULT_LANE_WIDTH_M  # the lane width of the last frame [m]
        self._ego_speed: float | None = None  # the ego's speed over the ground at the last frame [m/s]
        # the ego's speed change dv over a frame, for a car keeping its own speed: x -= dv dt / 2, x' -= dv
        self._B = np.array([[-dt_s / 2], [-1.0], [0.0], [0.0]])
        # white acceleration: Q = q^2 [[dt^4/4, dt^3/2], [dt^3/2, dt^2]] per axis
        self._block = np.array([[dt_s ** 4 / 4, dt_s ** 3 / 2], [dt_s ** 3 / 2, dt_s ** 2]])
        # Track.seen_bits of the frames within lateral_coast_s before the current one: bits 1..k
        self._coast_bits = ((1 << round(cfg.lateral_coast_s / dt_s)) - 1) << 1

    def reset(self) -> None:
        self.tracks.clear()
        self._next_id = 1
        self._ego_speed = None

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

    def step(self, detections: dict[str, list[Detection]], width_m: float, ego_speed_mps: float | None = None
             ) -> None:
        """One frame: predict every track, associate each rig's detections (``detections``: rig name -> its
        detections), make new tracks, keep the blind band's tracks and drop the lost ones. ``ego_speed_mps``: the
        ego's speed over the ground [m/s]; its change since the last frame moves the relative speed of a track flagged
        as cutting in (``_takes_ego_input``), None: taken as unchanged."""
        window = (1 << self.recent_frames) - 1
        # the ego's speed change over the frame [m/s]
        dv = 0.0 if ego_speed_mps is None or self._ego_speed is None else ego_speed_mps - self._ego_speed
        self._ego_speed = ego_speed_mps
        inputs = {True: np.array([[dv]]), False: np.zeros((1, 1))}  # made once a frame, not once a track
        for t in self.tracks:
            q = self.cfg.manoeuvre_accel_noise_mps2 if self.manoeuvring(t) else self.cfg.lateral_accel_noise_mps2
            t.kf.Q[2:, 2:] = self._block * q ** 2
            u = inputs[self._takes_ego_input(t)]
            t.kf.predict(u=u, B=self._B)
            if t.held is not None:
                t.held[0].predict(u=u, B=self._B)
            t.camera, t.box_px = None, None
            t.seen_bits = (t.seen_bits << 1) & window
        self.width = width_m
        for rig, dets in detections.items():
            self._associate(rig, dets)
        self._merge()
        self._keep_or_drop(width_m)

    @staticmethod
    def _takes_ego_input(t: Track) -> bool:
        """Whether the ego's speed change over the frame is the prediction's control input for track ``t``: for a
        track flagged as cutting in only. The car cutting in is what the ego brakes
        for and keeps its own speed over the ground, so a braking ego closes on it more slowly, and once it is too
        near to be seen its gap would otherwise be predicted shut; the other neighbours mostly slow with the ego (it
        brakes when the traffic does), and their relative speed is kept."""
        return t.warning

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
            if t.blind_s > 0 and t.takeover == 0 and not t.seen_bits:
                # a track held unseen for recent_s kept aside: a takeover that fails is undone (_hold_in_band)
                t.held = (deepcopy(t.kf), t.lane)
            R = self._noise(t, d)
            self._count_veer(t, d.lat_m - t.lat, float(t.kf.P[2, 2]) + R[1, 1])
            t.kf.update(np.array([[d.x_m], [d.lat_m]]), R=R)
            t.hits, t.misses = t.hits + 1, 0
            t.seen_bits |= 1
            # a held track leaves the band once a rig has seen it confirm_hits times in a row: a lone detection of
            # something else does not carry it off (the next unseen frame puts it back in the band)
            t.takeover = t.takeover + 1 if t.blind_s > 0 else 0
            if t.takeover >= c.confirm_hits:
                t.blind_s, t.takeover, t.held = 0.0, 0, None
            t.camera, t.box_px, t.cut_off = rig, d.box_px, d.cut_off
            # its lane: round(l / w)
            lane = int(round(t.lat / self.width))
            t.calm = t.calm + 1 if t.hits >= c.confirm_hits and abs(float(t.kf.x[3, 0])) < c.still_mps else 0
            t.still = lane == t.lane and t.still or t.calm >= c.still_frames
            t.settled = t.settled + 1 if lane == t.lane and t.still else int(t.still)
            t.lane = lane
            t.solid += int(not self._sliver(d))
            t.confirmed = t.confirmed or t.solid >= c.confirm_hits
        # a detection left over inside the gate of a track this rig measured this frame is another part of that car
        # (far away a car's face breaks into several groups): it makes no track of its own, nor does a sliver
        parts = {j for _, i, j in pairs if i in used_t}
        for j, d in enumerate(dets):
            if j not in used_d and j not in parts and not self._sliver(d):
                self.tracks.append(Track(self._next_id, self._new_filter(d), camera=rig, box_px=d.box_px))
                self._next_id += 1

    def _sliver(self, d: Detection) -> bool:
        """Whether detection ``d`` is too narrow for a car's face seen whole at its range (``min_face_width_m``
        within ``whole_face_m``): it may update a track but starts none, nor helps confirm one."""
        c = self.cfg
        return not d.cut_off and abs(d.x_m) <= c.whole_face_m and d.width_m < c.min_face_width_m

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
        a face that briefly takes in a car's side, or loses a lit part of its rear, jumps sideways by a metre; the
        along-lane one of a face at the near limit (``Detection.near_limit``), or of a sliver within ``near_sliver_m``,
        read farther away than the track widened to ``near_limit_sigma_m`` (the car is there or nearer)."""
        c = self.cfg
        # sigma_l^2 = sigma_0^2 + sigma_d^2; innovation variance S_l = P_ll + sigma_l^2
        var_l = c.lateral_sigma_m ** 2 + d.sigma_lat_m ** 2
        s_l = float(t.kf.P[2, 2]) + var_l
        nu = abs(d.lat_m - t.lat)
        k = c.outlier_sigmas
        if nu > k * np.sqrt(s_l):
            # widen R_l until nu = k sqrt(P_ll + R_l)
            var_l = max(var_l, (nu / k) ** 2 - float(t.kf.P[2, 2]))
        var_x = max(d.sigma_x_m, 0.05) ** 2
        # such a reading farther from the ego than the track, (x_d - x) sign(x_d) > 0, bounds its range from above only
        if (d.near_limit or self._sliver(d) and abs(d.x_m) < c.near_sliver_m) and (d.x_m - t.x) * np.sign(d.x_m) > 0:
            var_x = max(var_x, c.near_limit_sigma_m ** 2)
        return np.diag([var_x, var_l])

    def _hold_in_band(self, t: Track, lo_m: float, hi_m: float) -> None:
        """One frame of a track held unseen in a band from ``lo_m`` to ``hi_m`` along the lane [m]: unless it is
        flagged as cutting in (a car pulling out close by, in rain missed on several frames in a row, goes on moving
        over), or manoeuvres and a rig saw it within ``lateral_coast_s``, nothing says it moves sideways, so it keeps
        its lateral place; if its prediction reaches the band's edge with no rig seeing it come out, it has matched the
        ego's speed somewhere in the band: it stops there, anywhere in the band as far as its uncertainty goes. A
        takeover of a track held unseen for ``recent_s`` that is begun and not confirmed is undone: the detections that
        began it may have been of something else (a stray match at a rig's edge) and must not move the track across its
        lane or into the next (one missed on a frame or two, as in rain, takes its detections as they come)."""
        if t.held is not None:
            # unseen since it was kept aside, but for the detections undone
            t.kf, t.lane, t.seen_bits = *t.held, 0
            t.held = None
        if not (t.warning or self.manoeuvring(t) and t.seen_bits & self._coast_bits):
            t.kf.x[3, 0] = 0.0
        t.takeover = 0
        held = float(np.clip(t.x, lo_m, hi_m))
        if held != t.x:
            t.kf.x[0, 0], t.kf.x[1, 0] = held, 0.0
            t.kf.P[0, 0] = max(t.kf.P[0, 0], ((hi_m - lo_m) / 2) ** 2)
        t.blind_s += self.dt

    def _near_ahead(self, t: Track, width_m: float) -> bool:
        """Whether an unseen track is an established one ahead in the ego lane nearer than ``near_ahead_m``, or held
        already (its prediction reaching ``near_ahead_m`` stops there, as at the blind band's edge: a car pulling away
        too near to be found reads its gap long and would otherwise be dropped while still too near), held there for
        less than ``near_hold_s``."""
        c = self.cfg
        near = 0.0 < t.x and (t.x <= c.near_ahead_m or t.blind_s > 0)
        return t.hits >= c.min_settled and abs(t.lat) < 0.5 * width_m and near and t.blind_s < c.near_hold_s

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
        edge, coasts; an established one last seen cut off in the fringe and not heading for the band (its speed read
        from faces that are only in part in view) is held too (a car at the edge that vanishes has gone on into the
        band; a young one may be rain or a guard rail matched by chance at the edge, held beside for a minute); an
        established one in the ego lane nearer than ``near_ahead_m`` is held there for up to ``near_hold_s`` (a car
        that close may touch the ego's bumper unseen); any other counts a miss, and too many drop it."""
        c = self.cfg
        kept = []
        for t in self.tracks:
            if t.camera is None:
                beside = t.confirmed and abs(t.lat) >= 0.5 * width_m
                heading = self._heading_for_band(t)
                coasts = beside and (t.hits >= c.min_settled or t.cut_off) and heading
                into = self.in_blind_band(t.x, t.lat, width_m) or t.blind_s > 0 or (
                    t.cut_off and self._in_fringe(t) and not heading and t.hits >= c.min_settled)
                if beside and into and t.blind_s < c.max_blind_s:
                    self._hold_in_band(t, c.blind_behind_m, c.blind_ahead_m)
                elif not beside and self._near_ahead(t, width_m):
                    # no nearer than touching: x >= (L_ego + L_v) / 2
                    self._hold_in_band(t, (EGO_LENGTH_M + VEHICLE_LENGTH_M) / 2, c.near_ahead_m)
                elif not coasts:
                    t.misses += 1
            if t.misses <= (c.max_misses if t.confirmed else 1):
                kept.append(t)
        self.tracks = kept
