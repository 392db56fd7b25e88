"""The whole stack's cost (``percept bench --stack``): every vision slot in the closed loop on each scenario, one
thread, beside the stock composition of the peers on the same scenario's frames; the render cost per condition;
the closed loop's realtime factor with and without recording; and the memory of a long drive.

The stack is timed where it runs, with both rigs (the forward and the rear one) on every scenario: ``run_drive``
with every slot on vision over the scenario's first seconds (seed
0, so the sequence is fixed), which times each slot per frame under the run JSON's ``timing_ms`` keys and their
sum (``perception_total``). The peers are the stock way to do each job, on frames of the same scenario: OpenCV's
HOG ``detectMultiScale`` with its default people detector, ``StereoSGBM`` over the full frame, and a lane fit as
OpenCV tutorials write it (Canny edges, a probabilistic Hough transform in a trapezoid, a line fitted to each
side; the Udacity "finding lane lines" recipe). Their sum is the stock composition.
"""

from __future__ import annotations

import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import cv2
import numpy as np

from percept.drive.tasks import TASKS
from percept.sensors import Source

from .peers import topdown_ready
from .stages import cycle, median_ms

CONDITIONS = ("clear", "night", "rain", "glare", "noise")
"""The conditions whose render cost is timed."""
PAIR_FRAMES = 60
"""Frames whose stereo pairs are timed alone on each scenario; the figure is their median, which a few seconds'
slowdown of the machine barely moves."""
PERCEPTION_BUDGET_MS = 16.7
"""The whole perception stack's budget on one thread: 60 frames a second [ms/frame]."""
STACK_SPEEDUP = 20.0
"""How many times faster than the stock composition the perception stack must be."""
STEREO_PAIR_BUDGET_MS = 14.0
"""The budget of both stereo pairs together (the forward and the rear rig) on every scenario [ms]."""
REALTIME_RECORDED = 2.0
"""The closed loop with every vision slot and recording must run at least this many times real time, every drive."""
TARGETS = {"perception_total": f"perception total <= {PERCEPTION_BUDGET_MS:g} ms",
           "speedup": f">= {STACK_SPEEDUP:g}x the stock composition",
           "stereo_pair": f"both stereo pairs <= {STEREO_PAIR_BUDGET_MS:g} ms",
           "realtime_recorded": f"every recorded drive >= {REALTIME_RECORDED:g}x real time"}
"""The stack's targets, as ``StackCost.met`` names them, as a person reads them."""


def middle(values, key=None):
    """The median element of ``values`` (the lower of the middle two for an even count): one drive's figure, never an
    average of two."""
    return sorted(values, key=key)[(len(values) - 1) // 2]


@dataclass(frozen=True)
class StackCost:
    """The whole stack's cost on one scenario; the median of several drives is the middle one (``middle``)."""

    scenario: str  # scenario name
    frames: int  # frames each closed loop ran
    # the run JSON's timing_ms (render, each slot, perception_total) of the unrecorded drive with the median
    # perception_total [ms/frame]; its render is the mean over the loop's frames, each rendered after the slots ran
    timing_ms: dict
    # the median cost of both stereo pairs alone (SimWorld.observe: the renders and the ground truth) on the scenario's
    # first PAIR_FRAMES autopilot frames [ms]
    stereo_pair_ms: float
    # task name -> its bench_peer on the first of those frames, and "render" -> highway-env's top-down render
    # [ms/frame]
    peers_ms: dict
    # each drive's realtime factor without / with recording (the drives alternate, so that a change in the
    # machine's speed falls on both)
    realtime_factors: tuple[float, ...]
    realtime_factors_recording: tuple[float, ...]

    @property
    def realtime_factor(self) -> float:
        """The median drive's realtime factor without recording."""
        return middle(self.realtime_factors)

    @property
    def realtime_factor_recording(self) -> float:
        """The median drive's realtime factor with recording."""
        return middle(self.realtime_factors_recording)

    @property
    def stock_ms(self) -> float:
        """The stock composition: the sum of the tasks' peers [ms/frame]."""
        return sum(ms for k, ms in self.peers_ms.items() if k != "render")

    @property
    def speedup(self) -> float | None:
        """How many times faster the whole perception stack is than the stock composition."""
        total = self.timing_ms.get("perception_total")
        return self.stock_ms / total if total else None

    @property
    def met(self) -> dict[str, bool | None]:
        """Each of the stack's targets on this scenario: kept or not (None where its figure is missing)."""
        total, speedup = self.timing_ms.get("perception_total"), self.speedup
        return {"perception_total": None if total is None else total <= PERCEPTION_BUDGET_MS,
                "speedup": None if speedup is None else speedup >= STACK_SPEEDUP,
                "stereo_pair": self.stereo_pair_ms <= STEREO_PAIR_BUDGET_MS,
                "realtime_recorded": (min(self.realtime_factors_recording) >= REALTIME_RECORDED
                                      if self.realtime_factors_recording else None)}

    def to_dict(self) -> dict:
        """The JSON object of ``percept bench --json``'s ``stack`` list, figures rounded to 0.001."""
        r = lambda x: None if x is None else round(float(x), 3)  # noqa: E731
        return {"scenario": self.scenario, "frames": self.frames,
                "timing_ms": {k: r(v) for k, v in self.timing_ms.items()}, "stereo_pair_ms": r(self.stereo_pair_ms),
                "peers_ms": {k: r(v) for k, v in self.peers_ms.items()}, "stock_ms": r(self.stock_ms),
                "speedup": r(self.speedup), "realtime_factor": r(self.realtime_factor),
                "realtime_factor_recording": r(self.realtime_factor_recording),
                "realtime_factors": [r(x) for x in self.realtime_factors],
                "realtime_factors_recording": [r(x) for x in self.realtime_factors_recording], "met": self.met}


def _drive(scenario: str, seconds: float, record: Path | None = None, progress: Callable[[], None] | None = None,
           each_frame: Callable[[int], None] | None = None) -> dict:
    """One closed loop (seed 0) with every slot on vision, recorded to ``record`` when given (then
    ``each_frame(frame_index)`` is called after each step is recorded)."""
    from percept.sims import WorldConfig

    from percept.drive.config import DriveConfig
    from percept.drive.loop import run_drive

    cfg = DriveConfig(WorldConfig(scenario, seed=0), duration_s=seconds,
                      sources={t.name: Source.VISION for t in TASKS}, rear=True)
    tick = (lambda i, n: progress()) if progress else None
    if record is None:
        return run_drive(cfg, progress=tick)
    made = []

    def factory(world):
        from percept.review import RecordOptions, RunRecorder

        recorder = RunRecorder(record, world.cfg.rig, world.road_geometry.lane_lines, cfg.tasks, RecordOptions())
        made.append(_Ticking(recorder, each_frame))
        return made[0]

    try:
        return run_drive(cfg, recorder_factory=factory, progress=tick)
    finally:
        if made:
            made[0].inner.close()


class _Ticking:
    """A recorder that also calls ``each_frame(frame_index)`` after each step it records."""

    def __init__(self, inner, each_frame: Callable[[int], None] | None):
        self.inner, self.each_frame = inner, each_frame

    def log_step(self, frame, truth, step) -> None:
        self.inner.log_step(frame, truth, step)
        if self.each_frame is not None:
            self.each_frame(frame.index)


def _peer_frames(scenario: str, frames: int, pair_frames: int = PAIR_FRAMES) -> tuple[list, float, float]:
    """The first ``frames`` frames of ``scenario`` (autopilot, seed 0, both rigs), the median cost of observing each of
    the first ``pair_frames`` (both stereo pairs and the ground truth) and highway-env's top-down render's median
    [ms]."""
    from percept.sims import SimWorld, WorldConfig, with_rear

    world = topdown_ready(SimWorld(with_rear(WorldConfig(scenario, seed=0, autopilot=True), True)))
    shots, pair_ms = [], []
    for k in range(max(frames, pair_frames)):
        t0 = time.perf_counter()
        frame = world.observe()[0]
        pair_ms.append((time.perf_counter() - t0) * 1e3)
        if k < frames:
            shots.append(frame)
        world.step()
    pair_ms = pair_ms[:pair_frames]
    top_ms = median_ms(world.env.render, min(frames, 10))
    world.env.close()
    return shots, float(np.median(pair_ms)), top_ms


def bench_stack(scenario: str, seconds: float = 10.0, peer_frames: int = 20, repeats: int = 3,
                progress: Callable[[], None] | None = None) -> StackCost:
    """The whole vision stack on ``scenario`` in the closed loop, ``repeats`` times without and with recording
    (alternating), and the peers."""
    runs, recorded = [], []
    for _ in range(repeats):
        runs.append(_drive(scenario, seconds, progress=progress))
        with tempfile.TemporaryDirectory() as tmp:
            recorded.append(_drive(scenario, seconds, Path(tmp) / "bench.rrd", progress=progress))
    # the stage timings of the median unrecorded drive by perception_total, whole, so that they still add up
    typical = middle(runs, key=lambda r: r["timing_ms"]["perception_total"] or 0.0)
    shots, pair_ms, top_ms = _peer_frames(scenario, peer_frames)
    peers, shot = {}, cycle(shots, None)
    for task in (t for t in TASKS if t.bench_peer is not None):
        _, fn = task.bench_peer(shots)
        peers[task.name] = median_ms(lambda: fn(shot()), len(shots))
    peers["render"] = top_ms
    return StackCost(scenario, typical["frames"], typical["timing_ms"], pair_ms, peers,
                     tuple(r["realtime_factor"] for r in runs), tuple(r["realtime_factor"] for r in recorded))


def render_per_condition(frames: int = 20, scenario: str = "highway") -> dict:
    """Median cost [ms] of one stereo pair with each condition's effects (``SimWorld.observe``: the render, the
    condition applied to both images, the ground truth), on ``scenario``'s autopilot frames."""
    from percept.sims import SimWorld, WorldConfig, check_condition

    out = {}
    for cond in CONDITIONS:
        world = SimWorld(WorldConfig(scenario, seed=0, condition=check_condition(cond), autopilot=True))
        times = []
        for _ in range(frames):
            t0 = time.perf_counter()
            world.observe()
            times.append((time.perf_counter() - t0) * 1e3)
            world.step()
        world.env.close()
        out[cond] = float(np.median(times))
    return out


def soak(minutes: float, scenario: str = "highway", progress: Callable[[], None] | None = None) -> dict:
    """Resident memory [MB] of the process through a recorded closed loop of ``minutes`` simulated minutes with
    every slot on vision, sampled as the drive starts, each simulated minute and once the recording has closed;
    ``growth_mb``: the last sample less the first; ``mb_per_minute``: the least-squares slope of the samples taken
    while it drives from the first minute on (the first minute holds the slots' and renderer's first allocations),
    None for a drive under two minutes."""
    from percept.sensors.frame import FRAME_RATE_HZ

    samples = []

    def sample(index: int) -> None:
        if index % (60 * FRAME_RATE_HZ) == 0:
            samples.append(_rss_mb())

    with tempfile.TemporaryDirectory() as tmp:
        run = _drive(scenario, 60.0 * minutes, Path(tmp) / "soak.rrd", progress=progress, each_frame=sample)
    driving = samples[1:]
    samples.append(_rss_mb())
    slope = float(np.polyfit(np.arange(len(driving)), driving, 1)[0]) if len(driving) >= 2 else None
    return {"scenario": scenario, "minutes": minutes, "frames": run["frames"], "rss_mb": [round(s, 1) for s in samples],
            "peak_mb": round(max(samples), 1), "growth_mb": round(samples[-1] - samples[0], 1),
            "mb_per_minute": None if slope is None else round(slope, 3),
            "realtime_factor": round(run["realtime_factor"], 3)}


def _rss_mb() -> float:
    """This process's resident memory [MB] (Linux /proc; the peak so far elsewhere)."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    except OSError:
        pass
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
