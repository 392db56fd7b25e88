"""Shared vocabulary: cameras, the stereo rig, poses and sensor frames. Pure numpy/OpenCV."""

from .camera import PinholeCamera
from .chessboard import CameraCalibration, calibrate_chessboards, chessboard_images, parse_pattern
from .frame import Frame, ImuSample
from .poses import Pose2D, Transform, rot_z, wrap_angle
from .rig import Side, StereoRig

__all__ = ["CameraCalibration", "Frame", "ImuSample", "PinholeCamera", "Pose2D", "Side", "StereoRig", "Transform",
           "calibrate_chessboards", "chessboard_images", "parse_pattern", "rot_z", "wrap_angle"]
