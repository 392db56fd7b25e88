"""Per-stage cost against named peers, measured in the same run on one thread.

Peers: highway-env's own top-down ``render()`` of a 640x480 frame for the stereo renderer.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass
from typing import Callable

import cv2
import numpy as np


@dataclass(frozen=True)
class StageCost:
    """stage: what was timed; ms: median milliseconds per call; peer: the peer's name and peer_ms its cost in the
    same run (None where no peer does the same job); ratio = ms / peer_ms; target_ms: the stage's budget, if any."""

    stage: str
    ms: float
    peer: str | None = None
    peer_ms: float | None = None
    target_ms: float | None = None

    @property
    def ratio(self) -> float | None:
        return self.ms / self.peer_ms if self.peer_ms else None

    def to_dict(self) -> dict:
        r = self.ratio
        return {"stage": self.stage, "ms": round(self.ms, 3), "peer": self.peer,
                "peer_ms": None if self.peer_ms is None else round(self.peer_ms, 3),
                "ratio": None if r is None else round(r, 3), "target_ms": self.target_ms}


def median_ms(fn: Callable[[], object], repeats: int, warmup: int = 2) -> float:
    """Median wall time of ``fn`` in milliseconds."""
    for _ in range(warmup):
        fn()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append((time.perf_counter() - t0) * 1e3)
    return float(np.median(times))


def bench_render(frames: int = 30, seed: int = 0, progress: Callable[[], None] | None = None) -> StageCost:
    """One stereo pair of the ``highway`` scenario vs highway-env's top-down render of the same world."""
    os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
    from percept.sims import SimWorld, WorldConfig
    from percept.sims.snapshot import scene_from_road

    cv2.setNumThreads(1)
    world = SimWorld(WorldConfig("highway", seed=seed, autopilot=True))
    world.env.render_mode = "rgb_array"
    world.env.config.update(screen_width=world.cfg.rig.camera.width, screen_height=world.cfg.rig.camera.height)
    scenes = []
    for _ in range(frames):
        world.step()
        scenes.append(scene_from_road(world.env.road, world.ego, world.ids))
    it = iter(range(10**9))

    def ours():
        world.renderer.render(scenes[next(it) % len(scenes)])
        if progress:
            progress()

    def peer():
        img = world.env.render()
        assert img is not None and img.shape[:2] == (world.cfg.rig.camera.height, world.cfg.rig.camera.width)
        if progress:
            progress()

    ms = median_ms(ours, frames)
    peer_ms = median_ms(peer, frames)
    world.env.close()
    return StageCost("render stereo pair 640x480", ms, "highway-env top-down render()", peer_ms, None)


def bench_lanes(frames: int = 30, seed: int = 0, progress: Callable[[], None] | None = None) -> StageCost:
    """The lanes stage (evidence, fit, tracking) on rendered ``curves`` frames, 640x480, one thread."""
    from percept.lanes import LaneDetector
    from percept.sims import SimWorld, WorldConfig

    cv2.setNumThreads(1)
    world = SimWorld(WorldConfig("curves", seed=seed, autopilot=True))
    shots = []
    for _ in range(frames):
        frame, _ = world.observe()
        shots.append(frame)
        world.step()
    det = LaneDetector(world.cfg.rig)
    it = iter(range(10**9))

    def ours():
        f = shots[next(it) % len(shots)]
        det.process(f.left, f.wheel_speed_mps, f.imu.yaw_rate_rps, world.dt)
        if progress:
            progress()

    return StageCost("lanes (640x480 frame)", median_ms(ours, frames), target_ms=3.0)
