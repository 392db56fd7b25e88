"""Control laws, one per file, shared by the vision and privileged slots: each reads records only and returns
``(command, debug)``."""

from .base import Controller, sideslip_for_curvature, steering_for_curvature
from .emergency_braking import EmergencyBraking, EmergencyBrakingDebug
from .evasion import EVASIVE_EVENTS, Evasion, EvasionConfig, EvasionDebug
from .following import Following, FollowingDebug
from .lane_change import LaneChange, LaneChangeConfig, LaneChangeDebug, Phase
from .lane_keeping import LaneKeeping, LaneKeepingDebug
from .lateral_path import LateralRef, MinJerkPath
from .mobil import Judgement, MobilConfig, idm_accel, judge
from .target import Target, in_target_lane, nearer, nearest_target

__all__ = ["EVASIVE_EVENTS", "Controller", "EmergencyBraking", "EmergencyBrakingDebug", "Evasion", "EvasionConfig",
           "EvasionDebug", "Following", "FollowingDebug", "Judgement", "LaneChange", "LaneChangeConfig",
           "LaneChangeDebug", "LaneKeeping", "LaneKeepingDebug", "LateralRef", "MinJerkPath", "MobilConfig", "Phase",
           "Target", "idm_accel", "in_target_lane", "judge", "nearer", "nearest_target", "sideslip_for_curvature",
           "steering_for_curvature"]
