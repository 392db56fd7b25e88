"""Neighbours: every vehicle in the ego lane and the lanes beside it, ahead, beside and behind, from the forward and
the rear stereo rigs.

The vision slot (``slot``): per rig, block matching over the band where vehicles within range stand (``points``),
the standing points grouped on a ground grid in the ego lane's coordinates (``clusters``), each group's face ranged
by subpixel direct alignment (``refine``); tracks (``track``) in a Kalman filter per vehicle, held by prediction in
the blind band beside the ego and handed over between the rigs (``tracker``); lanes, gaps, relative speeds and cut-in
warnings.
"""

from .clusters import DEFAULT_LANE_WIDTH_M, VEHICLE_LENGTH_M, ClusterConfig, Detection, find_vehicles, lane_coordinates
from .finder import RigFinder
from .points import BandStereo, PointsConfig, StandingPoints
from .refine import refine_face
from .slot import NeighbourConfig, NeighbourDebug, NeighbourSlot
from .tracker import NeighbourTracker, Track, TrackerConfig

__all__ = ["DEFAULT_LANE_WIDTH_M", "VEHICLE_LENGTH_M", "BandStereo", "ClusterConfig", "Detection", "NeighbourConfig",
           "NeighbourDebug", "NeighbourSlot", "NeighbourTracker", "PointsConfig", "RigFinder", "StandingPoints",
           "Track", "TrackerConfig", "find_vehicles", "lane_coordinates", "refine_face"]
