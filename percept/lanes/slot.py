"""The vision lateral slot: the left camera (and the car's motion) in, the ego path out."""

from __future__ import annotations

from percept.sensors import EgoMotionGate, EgoPath, Frame, StereoRig

from .detector import LaneConfig, LaneDebug, LaneDetector, Pace

CRAWL_MPS = 1.0
"""Below this wheel speed (walking pace) the car crawls: its tracked lane neither drifts nor restarts [m/s]."""
STANDING_MPS = 0.3
"""Below this wheel speed the car stands: its tracked lane is not predicted either [m/s] (6 sigma of the simulated
wheel-speed noise, 0.05 m/s)."""


def pace(speed_mps: float) -> Pace:
    """The car's pace from its (plausible) wheel speed."""
    return Pace.STANDING if speed_mps < STANDING_MPS else Pace.CRAWLING if speed_mps < CRAWL_MPS else Pace.DRIVING


class LaneSlot:
    """Slot interface (``reset``, ``step(frame, upstream) -> (EgoPath, LaneDebug)``) over ``LaneDetector``; the
    path is the tracked lane at the wheel speed, which the tracker also predicts with (with the gyro's yaw rate; a bad
    sample of either is held at the last plausible one, ``EgoMotionGate``); its pace (``pace``) tells the detector how
    far the lane can move."""

    def __init__(self, rig: StereoRig, dt_s: float, cfg: LaneConfig = LaneConfig()):
        self.detector = LaneDetector(rig, cfg)
        self.dt_s = dt_s
        self.motion = EgoMotionGate()

    def reset(self) -> None:
        self.detector.reset()
        self.motion.reset()

    def step(self, frame: Frame, upstream: dict) -> tuple[EgoPath, LaneDebug]:
        """One frame: the ego path (the tracked lane at the gated wheel speed) and what the detector saw."""
        m = self.motion.update(frame)
        est, debug = self.detector.process(frame.left, m.speed_mps, m.yaw_rate_rps, self.dt_s,
                                           pace=pace(m.speed_mps))
        return EgoPath(est, m.speed_mps), debug
