"""Lanes: lane-marking evidence -> curves in road coordinates -> offset, heading, curvature; lane keeping."""

from .detector import LaneConfig, LaneDebug, LaneDetector
from .evidence import Brightness, EvidenceConfig, MarkingExtractor, marking_brightness
from .fit import FitConfig, fit_lane
from .slot import LaneSlot
from .tracker import LaneTracker
from .types import LaneEstimate, LaneFit, MarkingEvidence

__all__ = ["Brightness", "EvidenceConfig", "FitConfig", "LaneConfig", "LaneDebug", "LaneDetector", "LaneEstimate",
           "LaneFit", "LaneSlot",
           "LaneTracker", "MarkingEvidence", "MarkingExtractor", "fit_lane", "marking_brightness"]
