"""Per-stage cost against named peers, measured in the same run on one thread. Stages are named by the run JSON's
``timing_ms`` keys: ``render`` and each task's timing key (its vision slot, from the slot table).

Peers: highway-env's own top-down ``render()`` of a 640x480 frame for the stereo renderer.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass, replace
from typing import Callable

import cv2
import numpy as np

from percept.drive.privileged import TruthFeed
from percept.drive.tasks import Task

from .peers import topdown_ready


@dataclass(frozen=True)
class StageCost:
    """One stage's cost beside its peer's, and its targets."""

    stage: str  # the timing_ms key
    what: str  # what was timed, as the table's legend prints it
    ms: float  # cost per call [ms]: a slot's mean per frame (``slot_ms``), else the median (``median_ms``)
    peer: str | None = None  # the peer's name (None where no peer does the same job)
    peer_ms: float | None = None  # the peer's cost in the same run [ms]
    target_ms: float | None = None  # the stage's budget [ms] (None: none)
    target_speedup: float | None = None  # how many times faster than its peer the stage must be (None: no target)

    @property
    def ratio(self) -> float | None:
        """ms / peer_ms (None without a peer)."""
        return self.ms / self.peer_ms if self.peer_ms else None

    @property
    def met(self) -> bool | None:
        """Whether the stage keeps its budget and its speed-up (None without a target)."""
        checks = []
        if self.target_ms is not None:
            checks.append(self.ms <= self.target_ms)
        if self.target_speedup is not None and self.peer_ms:
            # speed-up = peer_ms / ms
            checks.append(self.peer_ms >= self.target_speedup * self.ms)
        return all(checks) if checks else None

    def to_dict(self) -> dict:
        """The JSON object of ``percept bench --json``'s ``stages`` list, figures rounded to 0.001."""
        r = self.ratio
        return {"stage": self.stage, "what": self.what, "ms": round(self.ms, 3), "peer": self.peer,
                "peer_ms": None if self.peer_ms is None else round(self.peer_ms, 3),
                "ratio": None if r is None else round(r, 3), "target_ms": self.target_ms,
                "target_speedup": self.target_speedup, "met": self.met}


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


SLOT_PASSES = 3
"""Timed passes of a slot over its frames; the stage's cost is the median of their means."""


def slot_ms(slot, shots: list, passes: int = SLOT_PASSES, progress: Callable[[], None] | None = None) -> float:
    """Mean cost per frame [ms] of a stateful slot stepped through consecutive ``shots`` ((frame, upstream)
    pairs) from ``reset()``: one warm-up pass (caches, first allocations), then the median over ``passes`` passes
    of each pass's mean, so that one stall of the machine in one pass does not move the figure. Each pass gets
    fresh copies of the frames: what a frame converts once for every slot (its grey images) is paid in every pass,
    as the first slot to read it pays it in the loop."""
    means = []
    for i in range(passes + 1):
        fresh = [(replace(frame), upstream) for frame, upstream in shots]
        slot.reset()
        t0 = time.perf_counter()
        for frame, upstream in fresh:
            slot.step(frame, upstream)
            if progress:
                progress()
        if i:
            means.append((time.perf_counter() - t0) * 1e3 / len(shots))
    return float(np.median(means))


def bench_ticks(frames: int, slots: int, peers: int) -> int:
    """Progress ticks of a whole bench: the render and its peer, each slot's passes and each slot peer's calls."""
    return 2 * (frames + 2) + slots * (SLOT_PASSES + 1) * frames + peers * (frames + 2)


def cycle(items: list, progress: Callable[[], None] | None) -> Callable[[], object]:
    """A function that returns the next item each call (round robin), ticking ``progress``."""
    state = {"i": 0}

    def nxt():
        item = items[state["i"] % len(items)]
        state["i"] += 1
        if progress:
            progress()
        return item
    return nxt


def bench_render(frames: int = 30, seed: int = 0, progress: Callable[[], None] | None = None) -> StageCost:
    """One stereo pair of the ``highway`` scenario vs highway-env's top-down render of the same world."""
    os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
    from percept.sims import SimWorld, WorldConfig
    from percept.sims.snapshot import scene_from_road

    cv2.setNumThreads(1)
    world = topdown_ready(SimWorld(WorldConfig("highway", seed=seed, autopilot=True)))
    scenes = []
    for _ in range(frames):
        world.step()
        scenes.append(scene_from_road(world.env.road, world.ego, world.ids))
    scene = cycle(scenes, progress)
    size = (world.cfg.rig.camera.height, world.cfg.rig.camera.width)

    def peer():
        img = world.env.render()
        assert img is not None and img.shape[:2] == size
        if progress:
            progress()

    ms = median_ms(lambda: world.renderer.render(scene()), frames)
    peer_ms = median_ms(peer, frames)
    world.env.close()
    return StageCost("render", "stereo pair 640x480 (highway)", ms, "highway-env top-down render()", peer_ms)


def bench_task(task: Task, tasks: tuple[Task, ...], frames: int = 30, seed: int = 0,
               progress: Callable[[], None] | None = None) -> StageCost:
    """A task's vision slot on rendered frames of its bench scenario (640x480, both rigs, one thread); the slots
    upstream of it are privileged (computed beforehand, not timed). A slot keeps state from frame to frame (trackers, filters,
    a search spread over frames), so it is timed on consecutive frames from a reset, as its mean cost per frame
    (``slot_ms``); the stateless peer as its median."""
    from percept.drive.loop import slot_context
    from percept.sims import SimWorld, WorldConfig, with_rear

    if task.vision is None:
        raise ValueError(f"the {task.name} task has no vision slot to time")
    cv2.setNumThreads(1)
    world = SimWorld(with_rear(WorldConfig(task.bench_scenario, seed=seed, autopilot=True), True))
    feed = TruthFeed()
    ctx = slot_context(world, feed)
    providers = {t.provides: t for t in tasks}
    upstream = {rec: providers[rec].privileged(ctx) for rec in task.reads}
    shots = []
    for _ in range(frames):
        frame, feed.truth = world.observe()
        shots.append((frame, {rec: s.step(frame, {})[0] for rec, s in upstream.items()}))
        world.step()
    ms = slot_ms(task.vision(ctx), shots, progress=progress)
    shot = cycle(shots, progress)
    peer, peer_ms = None, None
    if task.bench_peer is not None:
        peer, run = task.bench_peer([f for f, _ in shots])
        peer_ms = median_ms(lambda: run(shot()[0]), frames)
    return StageCost(task.name, f"{task.name} vision slot, 640x480 ({task.bench_scenario})", ms, peer,
                     peer_ms, task.budget_ms, task.bench_speedup if peer is not None else None)
