"""Longitudinal: range, range rate and time to contact of what is ahead; following and emergency braking inputs.

The vision slot (``slot``): the in-path obstacle finder (``obstacles``: coarse stereo in the band the path can
hold an obstacle, pixels that stand up in the corridor from the road plane refined online (``ground``), the nearest
group) and three measurements of it: the subpixel stereo range of the surface facing the ego (``refine``:
full-resolution surface mask, 1-D direct alignment), the range from where it meets the road (``contact``) and the
range rate from the expansion of its image (``flow``), fused in a Kalman filter (``range_filter``). Also the scoring
formulas (``metrics``) and dense stereo for ``percept stereo`` (``dense``).
"""

from .contact import Contact, ContactConfig, ContactRange
from .dense import DenseConfig, dense_disparity, row_misalignment_px, sgbm_disparity
from .flow import Expansion, ExpansionTracker, FlowConfig
from .ground import GroundConfig, GroundPlane
from .metrics import (BAD_PIXEL_PX, RANGE_BINS_M, bin_key, disparity_metrics, disparity_summary, range_abs_rel_err,
                      range_abs_rel_err_by_bin, ttc_abs_err_s)
from .obstacles import Obstacle, ObstacleConfig, ObstacleFinder
from .range_filter import RangeFilter
from .refine import PatchAligner, Refined, refine_disparity, surface_mask
from .slot import LeadConfig, LeadDebug, LongitudinalSlot

__all__ = ["BAD_PIXEL_PX", "Contact", "ContactConfig", "ContactRange", "DenseConfig", "Expansion", "ExpansionTracker",
           "FlowConfig", "GroundConfig", "GroundPlane", "LeadConfig", "LeadDebug", "LongitudinalSlot", "RANGE_BINS_M",
           "Obstacle", "ObstacleConfig", "ObstacleFinder", "PatchAligner", "RangeFilter", "Refined", "bin_key",
           "dense_disparity", "disparity_metrics", "disparity_summary", "range_abs_rel_err", "range_abs_rel_err_by_bin",
           "refine_disparity", "row_misalignment_px", "sgbm_disparity", "surface_mask", "ttc_abs_err_s"]
