"""Detection: pedestrians (HOG, constrained search, tracking) and their scoring."""

from .metrics import DetectionScore, FrameMatch, eligible, iou, iou_matrix, match_detections, score_frames

__all__ = ["DetectionScore", "FrameMatch", "eligible", "iou", "iou_matrix", "match_detections", "score_frames"]
