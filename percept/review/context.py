"""What the recorder and the task parts share: the recording options, entity paths, and the part interface.

A part draws one task's record. It is called once per frame as ``part(rec, ctx, estimate, debug, truth)``:
``rec`` the ``rr.RecordingStream`` (time already set), ``ctx`` a ``PartContext``, ``estimate`` / ``debug`` what the
task's slot returned (either may be None), ``truth`` the frame's ``StepTruth`` (truth: GroundTruth, in_path:
Obstacle or None, the commands). A part logs its scalars under ``<task>/<key>/<series>``, what it draws on the
left image under ``world/ego/camera/left/<task>/`` (in stored-image pixels, ``ctx.px(uv)``; only on frames with
``ctx.image``, so that it never lags the image; on the rear rig's left image likewise under
``world/ego/camera/rear_left/<task>/``, ``ctx.on_rear_image(name)``, on frames with ``ctx.rear_image``), what it
draws around the car under ``world/ego/<task>/`` (vehicle frame) and anything in the world frame
under ``world/<task>/``. A ``Part`` also names its plots and 3D trails so that the blueprint can lay them out;
a plain callable gets one time-series view of everything under ``<task>/``. What a part draws every frame goes
through ``ctx.buffer`` (``ctx.scalars``, ``ctx.buffer.clear``, ``ctx.buffer.add``: sent as columns, a tenth of the
cost of ``rec.log``); what it draws now and then may use ``rec.log``.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import rerun as rr

from percept.sensors import StereoRig
from percept.sensors.vehicle import EGO_LENGTH_M

from .series import ColumnBuffer

TIMELINE = "sim_time"
EGO = "world/ego"
CAMERA = "world/ego/camera/left"
REAR_CAMERA = "world/ego/camera/rear_left"
TRUTH_RGB = (190, 190, 190)
ESTIMATE_RGB = (255, 150, 30)
TRUTH_VS_ESTIMATE = (("truth", TRUTH_RGB), ("estimate", ESTIMATE_RGB))


@dataclass(frozen=True)
class RecordOptions:
    """camera_hz: how often the left image (and what the parts draw on it) is stored [Hz]; the frame rate or more
    stores every frame; jpeg_quality: JPEG quality of the stored image, 1..100; image_scale: stored image size
    relative to the camera's, 0.1..1 (0.5 = half width and height). Validated on construction (ValueError naming
    the bad value). The defaults keep a highway run with the vision lanes slot near 7 MB per simulated minute
    (every frame at full size and quality 70: about 26 MB)."""

    camera_hz: float = 5.0
    jpeg_quality: int = 70
    image_scale: float = 0.75

    def __post_init__(self) -> None:
        hz, q, s = self.camera_hz, self.jpeg_quality, self.image_scale
        if isinstance(hz, bool) or not isinstance(hz, numbers.Real) or not (math.isfinite(hz) and hz > 0):
            raise ValueError(f"camera_hz must be a positive number of images per second, got {hz!r}")
        if isinstance(q, bool) or not isinstance(q, numbers.Integral) or not 1 <= q <= 100:
            raise ValueError(f"jpeg_quality must be a whole number from 1 to 100, got {q!r}")
        if isinstance(s, bool) or not isinstance(s, numbers.Real) or not (math.isfinite(s) and 0.1 <= s <= 1):
            raise ValueError(f"image_scale must be from 0.1 to 1 (1 = the camera's size), got {s!r}")


@dataclass(frozen=True)
class PartContext:
    """task: the task's name (root of its entities); rig: the stereo rig; buffer: the recorder's rows sent as
    columns (what is drawn every frame: ``scalars``, clears, trails, what is around the car; the recorder sets each
    frame's time and sends them, so a part never holds a buffer of its own that nobody sends); image: this frame
    stores a left image; image_scale: stored pixels per camera pixel (both rigs); memory: the part's own state across
    frames (a dict it may fill); rear_rig: the rear-facing rig (None: the car has none); rear_image: this frame
    stores the rear rig's left image."""

    task: str
    rig: StereoRig
    buffer: ColumnBuffer
    image: bool = False
    image_scale: float = 1.0
    memory: dict = field(default_factory=dict)
    rear_rig: StereoRig | None = None
    rear_image: bool = False

    def px(self, uv_px) -> np.ndarray:
        """Camera pixels (N, 2) (u, v) -> stored-image pixels."""
        return np.asarray(uv_px, dtype=float).reshape(-1, 2) * self.image_scale

    def on_image(self, name: str) -> str:
        return f"{CAMERA}/{self.task}/{name}"

    def on_rear_image(self, name: str) -> str:
        return f"{REAR_CAMERA}/{self.task}/{name}"

    def around_ego(self, name: str) -> str:
        return f"{EGO}/{self.task}/{name}"

    def scalars(self, key: str, **series: float | None) -> None:
        """Log ``<task>/<key>/<name>`` for each series (through ``buffer``); None (or not finite) breaks the line
        there."""
        for name, value in series.items():
            self.buffer.scalar(f"{self.task}/{key}/{name}", value)

    def camera_x_m(self) -> float:
        """Vehicle-frame x of the left camera [m] (ranges in the records are measured from it)."""
        return float(self.rig.mount_x_m)

    def range_from_gap_m(self, gap_m: float) -> float:
        """Bumper gap [m] -> left-camera range [m] (the inverse of ``sensors.vehicle.bumper_gap_m``)."""
        # the bumper is half a body length ahead of the centre, the camera mount_x ahead of the centre
        return gap_m + EGO_LENGTH_M / 2 - self.rig.mount_x_m


@dataclass(frozen=True)
class Plot:
    """One time-series view: key (entity under the task, e.g. "offset_m"), title with its unit, and the series
    drawn in it as (name, RGB); the first (the truth, or the command), or those named in ``wide``, are drawn wider,
    so that an estimate equal to it stays visible."""

    key: str
    title: str
    series: tuple[tuple[str, tuple[int, int, int]], ...] = TRUTH_VS_ESTIMATE
    wide: tuple[str, ...] | None = None  # the series drawn wide (None: the first)

    def is_wide(self, i: int) -> bool:
        """Whether the ``i``-th series is drawn wide."""
        return i == 0 if self.wide is None else self.series[i][0] in self.wide


@dataclass(frozen=True)
class Part:
    """A task's review part: ``draw(rec, ctx, estimate, debug, truth)`` per frame (see the module docstring);
    plots: its time-series views; trails: entities (full paths) the 3D view shows with their whole past; texts:
    TextLog entities for the event log; setup(rec, ctx): static logging once, before the first frame."""

    draw: Callable
    plots: tuple[Plot, ...] = ()
    trails: tuple[str, ...] = ()
    texts: tuple[str, ...] = ()
    setup: Callable | None = None

    def __call__(self, rec: rr.RecordingStream, ctx: PartContext, estimate, debug, truth) -> None:
        self.draw(rec, ctx, estimate, debug, truth)

    def style(self, rec: rr.RecordingStream, ctx: PartContext) -> None:
        """Name and colour every series (static), then the part's own ``setup``."""
        for plot in self.plots:
            for i, (name, rgb) in enumerate(plot.series):
                width = 3.0 if plot.is_wide(i) else 1.5
                rec.log(f"{ctx.task}/{plot.key}/{name}", rr.SeriesLines(names=name, colors=[rgb], widths=width),
                        static=True)
        if self.setup is not None:
            self.setup(rec, ctx)


def log_on_change(rec: rr.RecordingStream, ctx: PartContext, path: str, state, text: str | None,
                  level: str = rr.TextLogLevel.INFO) -> None:
    """A TextLog line ``text`` at ``path`` when ``state`` differs from the last frame's (initially None; text None:
    log nothing)."""
    key = ("log", path)
    if ctx.memory.get(key) == state:
        return
    ctx.memory[key] = state
    if text is not None:
        rec.log(path, rr.TextLog(text, level=level))


def cross_line(x_m: float, half_width_m: float = 1.5, n: int = 2) -> np.ndarray:
    """A line across the path on the ground at vehicle-frame x (n, 3) [m]."""
    y = np.linspace(-half_width_m, half_width_m, n)
    return np.column_stack([np.full(n, x_m), y, np.zeros(n)])
