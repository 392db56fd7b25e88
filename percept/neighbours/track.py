"""A neighbour track's settings and its state: the Kalman filter of one vehicle and its bookkeeping."""

from __future__ import annotations

from dataclasses import dataclass

from filterpy.kalman import KalmanFilter


@dataclass(frozen=True)
class TrackerConfig:
    """How tracks are made, kept and dropped."""

    accel_noise_mps2: float = 2.0  # along-lane white acceleration (1-sigma) [m/s^2]
    lateral_accel_noise_mps2: float = 0.8  # lateral white acceleration (1-sigma) [m/s^2]
    manoeuvre_accel_noise_mps2: float = 4.0  # ... while the track manoeuvres sideways (a car pulling out) [m/s^2]
    manoeuvre_sigmas: float = 1.0  # a lateral innovation beyond this many sigmas ...
    manoeuvre_frames: int = 2  # ... of one sign this many detections in a row starts a manoeuvre, which lasts
    # until an innovation of that sign falls under it [-]
    near_limit_sigma_m: float = 2.0  # the along-lane 1-sigma of a face at the matcher's near limit, or of a sliver
    # within near_sliver_m, read farther away than its track: it bounds the car's range from above only (a car nearer
    # is read at that limit; a sliver near by is a part of a car, whose face may be nearer) [m]
    near_sliver_m: float = 15.0  # a sliver nearer than this along the lane is read as such a bound [m]
    lateral_sigma_m: float = 0.12  # a detection's lateral position noise near by (1-sigma), added in quadrature to
    # the detection's own range-dependent sigma_lat_m [m]
    outlier_sigmas: float = 3.0  # a lateral innovation beyond this many sigmas is down-weighted to this size [-]
    gate_x_m: float = 3.0  # association gate along the lane, plus gate_x_rel of the range [m]
    gate_x_rel: float = 0.08  # ... [-]
    gate_l_m: float = 1.4  # association gate across it [m]
    confirm_hits: int = 3  # detections that confirm a track, slivers not counted
    min_face_width_m: float = 0.8  # a face seen whole (not cut off by the image's edge) narrower than this ...
    whole_face_m: float = 60.0  # ... within this range along the lane is a sliver: a car's face is wider there, while
    # a post, a marking's edge, rain or a patch of road matched by chance is not; farther away a car's face breaks into
    # narrower groups [m]
    max_misses: int = 6  # frames unseen (where a rig looks) that drop a track
    blind_behind_m: float = -14.0  # the blind band beside the ego, where a rig sees too little of a car to find it:
    # centres from here ...
    blind_ahead_m: float = 12.0  # ... to here, along the lane, in the lanes beside [m]
    fringe_m: float = 10.0  # beyond each end of the band, where a rig sees a car beside only in part (cut off by the
    # image's edge): an established track there heading for the band coasts unseen instead of counting misses [m]
    max_blind_s: float = 60.0  # longest a track is kept by prediction alone in the blind band [s]
    near_ahead_m: float = 8.0  # a car in the ego lane whose centre is nearer than this shows the front rig too little
    # of itself to be found on every frame (its face near the matcher's nearest depth, or cut off by the image's edge
    # as it pulls in) ...
    near_hold_s: float = 3.0  # ... so an established track unseen there is held by prediction, no nearer than
    # touching, for up to this long: braking opens the gap and the rig finds it again [s]
    min_settled: int = 10  # detections in a row in one lane, since the track was laterally still in it, that make it
    # a settled neighbour there (a car still moving over from the lane beyond is not) [-]
    still_mps: float = 0.3  # a track is laterally still once its lateral speed is below this [m/s] ...
    still_frames: int = 3  # ... on this many detections in a row since it was confirmed (its filter starts at rest) [-]
    lateral_coast_s: float = 0.2  # a held track seen by a rig this recently keeps its lateral speed while it
    # manoeuvres: in rain a car pulling out near the band is missed on one frame in three, and each miss would reset
    # its speed to rest; a still one's speed, read from rain-blurred faces, is noise that would carry it sideways [s]
    blind_spread_mps: float = 2.0  # how fast the along-lane uncertainty of a track in the band grows [m/s]
    recent_s: float = 1.0  # the window over which a track's detections are counted (Track.seen) [s]


@dataclass
class Track:
    """One vehicle's filter and bookkeeping."""

    track_id: int
    kf: KalmanFilter
    hits: int = 1
    solid: int = 1  # its detections that were no slivers (TrackerConfig.min_face_width_m)
    misses: int = 0
    blind_s: float = 0.0  # how long it has been held in the blind band (0: not held) [s]
    takeover: int = 0  # detections in a row since a rig saw it again while it was held
    held: tuple | None = None  # while a takeover is under way: (its filter as held unseen, predicted on; its lane)
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
