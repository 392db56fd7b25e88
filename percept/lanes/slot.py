"""The vision lateral slot: the left camera (and the car's motion) in, the ego path out."""

from __future__ import annotations

from percept.sensors import EgoMotionGate, EgoPath, Frame, StereoRig

from .detector import LaneConfig, LaneDebug, LaneDetector

STANDING_MPS = 0.3
"""Below this wheel speed the car stands still and its lane is held [m/s] (6 sigma of the simulated wheel-speed
noise, 0.05 m/s)."""


class LaneSlot:
    """Slot interface (``reset``, ``step(frame, upstream) -> (EgoPath, LaneDebug)``) over ``LaneDetector``; the
    path is the tracked lane at the wheel speed, which the tracker also predicts with (with the gyro's yaw rate; a bad
    sample of either is held at the last plausible one, ``EgoMotionGate``); below ``STANDING_MPS`` the car stands and
    the detector holds the lane."""

    def __init__(self, rig: StereoRig, dt_s: float, cfg: LaneConfig = LaneConfig()):
        self.detector = LaneDetector(rig, cfg)
        self.dt_s = dt_s
        self.motion = EgoMotionGate()

    def reset(self) -> None:
        self.detector.reset()
        self.motion.reset()

    def step(self, frame: Frame, upstream: dict) -> tuple[EgoPath, LaneDebug]:
        m = self.motion.update(frame)
        est, debug = self.detector.process(frame.left, m.speed_mps, m.yaw_rate_rps, self.dt_s,
                                           standing=m.speed_mps < STANDING_MPS)
        return EgoPath(est, m.speed_mps), debug
