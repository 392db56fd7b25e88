"""Rendered frames with their ground truth, from a closed-loop run on the privileged slots (so the ego drives as a
perfect stack would: it stops for people, follows leads): the training crops of the sim people model, and the
frames on which detectors are scored one by one.
"""

from __future__ import annotations

from typing import Callable

from percept.drive.config import DriveConfig
from percept.drive.loop import run_drive
from percept.sensors import Source
from percept.sims import WorldConfig, check_condition

FrameFn = Callable[[int, object, object], None]
"""fn(seed, frame, ground_truth): called with each sampled ``Frame`` and its ``GroundTruth``."""


class _Sampler:
    """A recorder for ``run_drive`` that hands every ``every``-th rendered frame and its truth to ``fn``."""

    def __init__(self, seed: int, every: int, fn: FrameFn):
        self.seed, self.every, self.fn = seed, every, fn

    def log_step(self, frame, truth, step) -> None:
        if frame.index % self.every == 0 and frame.left is not None:
            self.fn(self.seed, frame, truth.truth)


def for_each_frame(scenario: str, seeds, fn: FrameFn, every: int = 1, condition: str = "clear",
                   duration_s: float | None = None) -> None:
    """Drive ``scenario`` on the privileged slots for each seed and call ``fn`` on every ``every``-th rendered
    frame (dropped frames are skipped)."""
    if every < 1:
        raise ValueError(f"every must be a positive frame count, got {every}")
    cond = check_condition(condition)
    for seed in seeds:
        cfg = DriveConfig(WorldConfig(scenario, seed=int(seed), condition=cond), duration_s=duration_s,
                          default=Source.PRIVILEGED)
        run_drive(cfg, recorder_factory=lambda world, s=int(seed): _Sampler(s, every, fn))
