"""Odometry: stereo visual odometry fused with IMU and wheel speed; trajectory scoring."""

from .fusion import FusionNoise, PoseFilter
from .kitti_folder import KittiFolder, load_kitti_folder
from .landmarks import LandmarkFinder, LandmarkSighting, SightingConfig
from .metrics import (KITTI_LENGTH_FRACTIONS, as_matrices, ate_rmse_m, cumulative_distance_m, final_position_error_m,
                      kitti_drift, path_length_m, rotation_angle_rad)
from .mono_vo import MonoVO, MonoVOConfig
from .slot import OdometryDebug, OdometrySlot
from .stereo_vo import StereoVO, StereoVOConfig
from .trajectory_io import TrajectoryFormat, read_kitti_poses, read_tum, write_trajectory
from .types import Trajectory, VOStep

__all__ = ["FusionNoise", "KITTI_LENGTH_FRACTIONS", "LandmarkFinder", "LandmarkSighting", "OdometryDebug",
           "OdometrySlot", "PoseFilter", "SightingConfig", "StereoVO", "StereoVOConfig", "Trajectory", "VOStep",
           "as_matrices", "ate_rmse_m", "cumulative_distance_m", "final_position_error_m", "kitti_drift",
           "path_length_m", "rotation_angle_rad",
           "KittiFolder", "MonoVO", "MonoVOConfig", "TrajectoryFormat", "load_kitti_folder", "read_kitti_poses",
           "read_tum", "write_trajectory"]
