"""The vision lateral slot: the left camera (and the car's motion) in, the ego path out."""

from __future__ import annotations

from percept.sensors import EgoMotionGate, EgoPath, Frame, StereoRig

from .detector import LaneConfig, LaneDebug, LaneDetector


class LaneSlot:
    """Slot interface (``reset``, ``step(frame, upstream) -> (EgoPath, LaneDebug)``) over ``LaneDetector``; the
    path is the tracked lane at the wheel speed, which the tracker also predicts with (with the gyro's yaw rate; a bad
    sample of either is held at the last plausible one, ``EgoMotionGate``)."""

    def __init__(self, rig: StereoRig, dt_s: float, cfg: LaneConfig = LaneConfig()):
        self.detector = LaneDetector(rig, cfg)
        self.dt_s = dt_s
        self.motion = EgoMotionGate()

    def reset(self) -> None:
        self.detector.reset()
        self.motion.reset()

    def step(self, frame: Frame, upstream: dict) -> tuple[EgoPath, LaneDebug]:
        m = self.motion.update(frame)
        est, debug = self.detector.process(frame.left, m.speed_mps, m.yaw_rate_rps, self.dt_s)
        return EgoPath(est, m.speed_mps), debug
