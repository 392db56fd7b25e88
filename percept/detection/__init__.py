"""Detection: pedestrians (HOG features shared across windows, the image-pyramid search, tracking, scoring).

``hog``: Dalal & Triggs HOG blocks computed once per image and scale (OpenCV's gradients, summed into blocks by
``hog_blocks``) and a linear model scored over every window from them; ``pyramid``: the unconstrained search over
every scale (``percept detect``); ``constrained``: the search over the windows where a person standing on the road
can appear; ``tracking``: people tracked on the ground plane; ``slot``: the vision pedestrians slot;
``metrics``: the scoring formulas; ``overlay``: drawings.
"""

from .hog import DESCRIPTOR_LEN, WINDOW_PX, LinearModel, block_grid, hog_descriptor
from .blocks import hog_blocks
from percept.sensors.boxes import iou, iou_matrix

from .metrics import DetectionScore, FrameMatch, eligible, match_detections, score_frames
from .pyramid import Detection, detect_multiscale, group, pyramid_scales, windows_at_scale
from .constrained import ConstrainedSearch, SearchConfig, SearchStats, person_box
from .free_motion import FreeMotion
from .tracking import PersonTrack, PersonTracker, TrackConfig
from .slot import PedestrianDebug, PedestrianSlot, window_of

__all__ = ["ConstrainedSearch", "FreeMotion", "PedestrianDebug", "PedestrianSlot", "PersonTrack", "PersonTracker",
           "SearchConfig", "SearchStats", "TrackConfig", "person_box", "window_of",
           "DESCRIPTOR_LEN", "Detection", "DetectionScore", "FrameMatch", "LinearModel", "WINDOW_PX", "block_grid",
           "detect_multiscale", "eligible", "group", "hog_blocks", "hog_descriptor", "iou", "iou_matrix",
           "match_detections", "pyramid_scales", "score_frames", "windows_at_scale"]
