"""LaneDetector: one camera image (and the car's motion) in, a tracked LaneEstimate out."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from percept.sensors import StereoRig

from .evidence import EvidenceConfig, MarkingExtractor
from .fit import FitConfig, fit_lane
from .tracker import LaneTracker
from .types import LaneEstimate, LaneFit, MarkingEvidence


@dataclass(frozen=True)
class LaneDebug:
    """What the detector saw: evidence (None for a dropped frame), the frame's fit (None when too thin)."""

    evidence: MarkingEvidence | None
    fit: LaneFit | None


@dataclass(frozen=True)
class LaneConfig:
    evidence: EvidenceConfig = field(default_factory=EvidenceConfig)
    fit: FitConfig = field(default_factory=FitConfig)


class LaneDetector:
    """Marking evidence -> robust joint fit -> Kalman tracking. Works on the left camera of ``rig``."""

    def __init__(self, rig: StereoRig, cfg: LaneConfig = LaneConfig()):
        self.rig, self.cfg = rig, cfg
        self.extractor = MarkingExtractor(rig, cfg.evidence)
        self.tracker = LaneTracker(cfg.fit.width_prior_m, cfg.fit.curvature_rate_sigma_1pm2)

    def reset(self) -> None:
        self.tracker.reset()

    def process(self, image: np.ndarray | None, speed_mps: float = 0.0, yaw_rate_rps: float = 0.0,
                dt: float = 1.0 / 15, standing: bool = False) -> tuple[LaneEstimate, LaneDebug]:
        """Track the lane through one frame; ``image`` None (dropped frame) only predicts.

        ``standing``: the car stands still, so a tracked lane is held as it is (no prediction, no fit; the evidence
        is still extracted for review). A lane cannot move relative to a car that does not move, while fits of the
        few metres of road a standing car sees (behind a stopped lead, in rain) can lie a lane apart. A detector
        with no lane yet fits as usual."""
        if standing and self.tracker.initialised:
            return self.tracker.estimate, LaneDebug(None if image is None else self.extractor.extract(image), None)
        if self.tracker.initialised:
            self.tracker.predict(speed_mps, yaw_rate_rps, dt)
        if image is None:
            return self.tracker.estimate, LaneDebug(None, None)
        ev = self.extractor.extract(image)
        prior = self.tracker.estimate if self.tracker.initialised and self.tracker.confidence > 0.05 else None
        fit = fit_lane(ev, prior, self.cfg.fit)
        if prior is not None and (fit is None or fit.estimate.confidence < 0.3):
            # lost the lane around the prediction: search afresh
            fresh = fit_lane(ev, None, self.cfg.fit)
            if fresh is not None and (fit is None or fresh.estimate.confidence > fit.estimate.confidence):
                fit = fresh
                self.tracker.reset()
        if fit is not None:
            self.tracker.update(fit)
        return self.tracker.estimate, LaneDebug(ev, fit)
