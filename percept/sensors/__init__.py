"""Shared vocabulary: cameras, the stereo rig, poses and sensor frames. Pure numpy/OpenCV."""

from .boxes import check_boxes, iou, iou_matrix
from .camera import PinholeCamera
from .chessboard import CameraCalibration, calibrate_chessboards, chessboard_images, parse_pattern
from .footage import (IMAGE_SUFFIXES, VIDEO_SUFFIXES, FootageKind, Undistorter, VideoReader, decode_image,
                      list_footage, list_images, open_video, read_image)
from .ego_motion import (MAX_ACCEL_MPS2, MAX_SPEED_MPS, MAX_YAW_RATE_RPS, MIN_SPEED_MPS, EgoMotion, EgoMotionGate,
                         as_sample, plausible_accel, plausible_speed, plausible_yaw_rate)
from .frame import FRAME_RATE_HZ, Frame, ImuSample, to_gray
from .records import (EGO_LENGTH_M, BrakingRequest, EgoPath, LandmarkMap, LaneEstimate, Lead, Neighbour, Neighbours,
                      ObjectKind, PoseEstimate, Source, Zone, zone_and_gap)
from .poses import Pose2D, Transform, rot_z, rotate_to_vehicle, wrap_angle
from .rig import REAR_MOUNT_X_M, Side, StereoRig, rear_rig

__all__ = ["EGO_LENGTH_M", "BrakingRequest", "EgoPath", "LandmarkMap", "LaneEstimate", "Lead", "Neighbour", "Neighbours",
           "ObjectKind", "PoseEstimate", "Source", "Zone", "zone_and_gap",
           "IMAGE_SUFFIXES", "VIDEO_SUFFIXES", "FootageKind", "Undistorter", "VideoReader", "decode_image",
           "list_footage", "list_images", "open_video", "read_image",
           "CameraCalibration", "FRAME_RATE_HZ", "Frame", "ImuSample", "PinholeCamera", "Pose2D", "REAR_MOUNT_X_M", "Side", "StereoRig",
           "rear_rig",
           "Transform",
           "calibrate_chessboards", "check_boxes", "chessboard_images", "iou", "iou_matrix", "parse_pattern", "rot_z",
           "rotate_to_vehicle", "to_gray", "wrap_angle",
           "MAX_ACCEL_MPS2", "MAX_SPEED_MPS", "MAX_YAW_RATE_RPS", "MIN_SPEED_MPS", "EgoMotion", "EgoMotionGate",
           "as_sample", "plausible_accel", "plausible_speed", "plausible_yaw_rate"]
