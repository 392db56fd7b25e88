"""Odometry: stereo visual odometry fused with IMU and wheel speed; trajectory scoring."""

from .fusion import FusionNoise, PoseFilter
from .landmarks import LandmarkFinder, LandmarkSighting, SightingConfig
from .metrics import (KITTI_LENGTH_FRACTIONS, as_matrices, ate_rmse_m, cumulative_distance_m, final_position_error_m,
                      kitti_drift, path_length_m, rotation_angle_rad)
from .slot import OdometryDebug, OdometrySlot
from .stereo_vo import StereoVO, StereoVOConfig
from .types import Trajectory, VOStep

__all__ = ["FusionNoise", "KITTI_LENGTH_FRACTIONS", "LandmarkFinder", "LandmarkSighting", "OdometryDebug",
           "OdometrySlot", "PoseFilter", "SightingConfig", "StereoVO", "StereoVOConfig", "Trajectory", "VOStep",
           "as_matrices", "ate_rmse_m", "cumulative_distance_m", "final_position_error_m", "kitti_drift",
           "path_length_m", "rotation_angle_rad"]
