"""The vision lateral slot: the left camera (and the car's motion) in, the ego path out."""

from __future__ import annotations

from percept.sensors import EgoPath, Frame, StereoRig

from .detector import LaneConfig, LaneDebug, LaneDetector


class LaneSlot:
    """Slot interface (``reset``, ``step(frame, upstream) -> (EgoPath, LaneDebug)``) over ``LaneDetector``; the
    path is the tracked lane at the wheel speed, which the tracker also predicts with."""

    def __init__(self, rig: StereoRig, dt_s: float, cfg: LaneConfig = LaneConfig()):
        self.detector = LaneDetector(rig, cfg)
        self.dt_s = dt_s

    def reset(self) -> None:
        self.detector.reset()

    def step(self, frame: Frame, upstream: dict) -> tuple[EgoPath, LaneDebug]:
        est, debug = self.detector.process(frame.left, frame.wheel_speed_mps, frame.imu.yaw_rate_rps, self.dt_s)
        return EgoPath(est, frame.wheel_speed_mps), debug
