"""LaneDetector: one camera image (and the car's motion) in, a tracked LaneEstimate out."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum

import numpy as np

from percept.sensors import StereoRig
from percept.sensors.frame import FRAME_RATE_HZ

from .evidence import EvidenceConfig, MarkingExtractor
from .fit import FitConfig, fit_lane
from .tracker import LaneTracker
from .types import LaneEstimate, LaneFit, MarkingEvidence


class Pace(Enum):
    """How the car moves over the road it sees (the lateral slot tells it from the wheel speed): DRIVING; CRAWLING,
    at walking pace or less, where the tracked lane neither drifts nor restarts; STANDING, where it does not move
    at all (no prediction: the gyro's bias must not turn the lane of a car that stands)."""

    DRIVING = "driving"
    CRAWLING = "crawling"
    STANDING = "standing"


@dataclass(frozen=True)
class LaneDebug:
    """What the detector saw: evidence (None for a dropped frame), the frame's fit (None when too thin)."""

    evidence: MarkingEvidence | None
    fit: LaneFit | None


@dataclass(frozen=True)
class LaneConfig:
    """Settings of the lane detector."""

    evidence: EvidenceConfig = field(default_factory=EvidenceConfig)  # the marking evidence's settings
    fit: FitConfig = field(default_factory=FitConfig)  # the joint fit's settings (its width prior also the tracker's)


class LaneDetector:
    """Marking evidence -> robust joint fit -> Kalman tracking. Works on the left camera of ``rig``."""

    def __init__(self, rig: StereoRig, cfg: LaneConfig = LaneConfig()):
        self.rig, self.cfg = rig, cfg
        self.extractor = MarkingExtractor(rig, cfg.evidence)
        self.tracker = LaneTracker(cfg.fit.width_prior_m, cfg.fit.curvature_rate_sigma_1pm2)

    def reset(self) -> None:
        self.tracker.reset()

    def process(self, image: np.ndarray | None, speed_mps: float = 0.0, yaw_rate_rps: float = 0.0,
                dt: float = 1.0 / FRAME_RATE_HZ, pace: Pace = Pace.DRIVING) -> tuple[LaneEstimate, LaneDebug]:
        """Track the lane through one frame; ``image`` None (dropped frame) only predicts.

        ``pace`` CRAWLING or STANDING: the lane moves relative to the car by the car's own motion alone (none when
        standing), so the tracked lane is predicted without the per-second drift (not at all when standing) and is
        not searched for afresh: each fit is taken around it and averaged into it, never restarting it, because
        behind a stopped lead (in rain above all) the few metres of road the camera sees give fits that can lie a
        lane apart, and a fresh search would swing the lane, the steering and the corridor under a car that does
        not move."""
        held = pace is not Pace.DRIVING and self.tracker.initialised
        if self.tracker.initialised and pace is not Pace.STANDING:
            self.tracker.predict(speed_mps, yaw_rate_rps, dt, drift=not held)
        if image is None:
            return self.tracker.estimate, LaneDebug(None, None)
        ev = self.extractor.extract(image)
        tracked = self.tracker.initialised and (held or self.tracker.confidence > 0.05)
        prior = self.tracker.estimate if tracked else None
        fit = fit_lane(ev, prior, self.cfg.fit)
        if prior is not None and not held and (fit is None or fit.estimate.confidence < 0.3):
            # lost the lane around the prediction: search afresh
            fresh = fit_lane(ev, None, self.cfg.fit)
            if fresh is not None and (fit is None or fresh.estimate.confidence > fit.estimate.confidence):
                fit = fresh
                # the fresh lane may be another than the one tracked: index + round((offset_pred - offset_new) / w)
                moved = round((prior.offset_m - fresh.estimate.offset_m) / max(prior.width_m, 1.0))
                self.tracker.reset(index=self.tracker.index + moved)
        if fit is not None:
            self.tracker.update(fit)
        return self.tracker.estimate, LaneDebug(ev, fit)
