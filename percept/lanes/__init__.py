"""Lanes: lane-marking evidence -> curves in road coordinates -> offset, heading, curvature; lane keeping."""

from .detector import LaneConfig, LaneDebug, LaneDetector, Pace
from .evidence import Brightness, EvidenceConfig, MarkingExtractor, marking_brightness
from .fit import FitConfig, fit_lane
from .footage_geometry import FootageGeometry, footage_geometry
from .hood import hood_row
from .slot import CRAWL_MPS, STANDING_MPS, LaneSlot, pace
from .tracker import LaneTracker
from .tusimple import h_samples, tusimple_record
from .types import LaneEstimate, LaneFit, MarkingEvidence

__all__ = ["CRAWL_MPS", "STANDING_MPS", "Brightness", "EvidenceConfig", "FitConfig", "FootageGeometry", "LaneConfig",
           "LaneDebug", "LaneDetector", "LaneEstimate", "LaneFit", "LaneSlot", "LaneTracker", "MarkingEvidence",
           "MarkingExtractor", "Pace", "fit_lane", "footage_geometry", "h_samples", "hood_row", "marking_brightness",
           "pace", "tusimple_record"]
