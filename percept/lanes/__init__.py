"""Lanes: lane-marking evidence -> curves in road coordinates -> offset, heading, curvature; lane keeping."""

from .detector import LaneConfig, LaneDebug, LaneDetector
from .evidence import EvidenceConfig, MarkingExtractor
from .fit import FitConfig, fit_lane
from .tracker import LaneTracker
from .types import LaneEstimate, LaneFit, MarkingEvidence

__all__ = ["EvidenceConfig", "FitConfig", "LaneConfig", "LaneDebug", "LaneDetector", "LaneEstimate", "LaneFit",
           "LaneTracker", "MarkingEvidence", "MarkingExtractor", "fit_lane"]
