"""Odometry: stereo visual odometry fused with IMU and wheel speed; trajectory scoring."""

from .metrics import (KITTI_LENGTH_FRACTIONS, as_matrices, ate_rmse_m, cumulative_distance_m, final_position_error_m,
                      kitti_drift, path_length_m, rotation_angle_rad)

__all__ = ["KITTI_LENGTH_FRACTIONS", "as_matrices", "ate_rmse_m", "cumulative_distance_m", "final_position_error_m",
           "kitti_drift", "path_length_m", "rotation_angle_rad"]
