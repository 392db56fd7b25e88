"""Rerun recording of a drive: what every run has, then one part per task (``percept.review.parts``).

Timeline ``sim_time`` in simulation seconds. Every recording has ``world`` (z up; object-kind annotation
context), ``world/road`` (lane lines, static), ``world/ego`` (the ego pose, per frame; ``world/ego/body`` its
box, static), ``world/ego/camera/left`` (mount and pinhole, static; the JPEG image at ``RecordOptions.camera_hz``),
with a rear rig ``world/ego/camera/rear_left`` (the same for the rear rig's left camera, on frames that have its
pair), ``world/ego/objects`` (true 3D boxes in the vehicle frame), ``world/ego/camera/left/objects`` and
``world/ego/camera/rear_left/objects`` (their true boxes in each image; ``cameras.CameraStore``),
``world/trajectory`` (one true position per frame; the 3D view shows its whole past) and the control part's
``control/*``. Each task part adds ``<task>/*`` scalars and its drawings (see ``percept.review.context``).
The drive is streamed to a temporary name beside the target (``.RUN.rrd.part``) without an RRD footer, the manifest
of its chunks that Rerun's SDK would hold in memory, a row per chunk, until the file closes. ``close`` then writes a
finished run's stream compacted and with its footer to ``RUN.rrd`` (``finish``: ``rerun rrd optimize`` in a child
process, to a temporary name, then renamed), so that the drive's memory stays flat and the finished recording
passes ``rerun rrd verify``; an interrupted or failed run's stream becomes ``RUN.partial.rrd`` as it is (no
footer: the viewer reads it from its start as it reads any file cut short), and a finished recording is never
replaced by a truncated one.
"""

from __future__ import annotations

import importlib
import importlib.util
import os
import subprocess
import sys
import time
from dataclasses import replace
from datetime import timedelta
from pathlib import Path

import numpy as np
import rerun as rr

from percept.outputs import atomic_path
from percept.sensors import StereoRig
from percept.sensors.vehicle import EGO_LENGTH_M, EGO_WIDTH_M

from . import parts, space
from .blueprint import TRAJECTORY, blueprint
from .cameras import KIND_CLASSES, CameraStore
from .context import CAMERA, EGO, REAR_CAMERA, TIMELINE, Part, PartContext, RecordOptions
from .series import ColumnBuffer

OBJECTS = f"{EGO}/objects"
TRAJECTORY_RGB = (60, 220, 90)
EGO_HEIGHT_M = 1.5
"""Height of the ego's box as drawn [m]."""
BATCHING = dict(flush_tick=timedelta(seconds=5), flush_num_bytes=8 << 20)
"""Few, large chunks: each chunk carries its own schema (about 2 KB), which the default batching (a chunk per
entity every 200 ms of wall time) would repeat thousands of times in a file."""
COLUMNS_FLUSH_S = 10.0
"""Simulated time the per-frame rows (scalars, clears, the ego's transform, trail points, what the parts draw around
the car) are held before they are sent as columns (``series.ColumnBuffer``: a chunk per entity)."""


FLUSH_TIMEOUT_S = 30.0
"""Longest wait for the stream's last chunks to reach the disk when the run ends [s]."""
WATCH_S = 1.0
"""Wall time between two looks at the free space of the recording's disk [s]."""
ABANDONED: list[rr.RecordingStream] = []
"""Streams given up on a full disk (``RunRecorder._drop``), kept from their finaliser for as long as the process
lives."""


def resolve_part(spec):
    """A task's ``recorder``: a callable, or "module:function" imported here."""
    if callable(spec):
        return spec
    module, sep, name = str(spec).partition(":")
    if not sep or not module or not name:
        raise ValueError(f"a recorder part must be a callable or 'module:function', got {spec!r}")
    try:
        part = getattr(importlib.import_module(module), name)
    except (ImportError, AttributeError) as e:
        raise ValueError(f"cannot load the recorder part {spec!r}: {e}") from None
    if not callable(part):
        raise ValueError(f"the recorder part {spec!r} is not callable")
    return part


def partial_path(path: Path) -> Path:
    """Where an interrupted recording of ``path`` is kept: RUN.rrd -> RUN.partial.rrd."""
    return path.with_name(f"{path.stem}.partial{path.suffix or '.rrd'}")


def rerun_cli() -> str:
    """The ``rerun`` command-line binary that rerun-sdk's wheel ships (package ``rerun_cli``); OSError without it."""
    spec = importlib.util.find_spec("rerun_cli")
    if spec is not None and spec.origin:
        exe = Path(spec.origin).with_name("rerun.exe" if sys.platform == "win32" else "rerun")
        if exe.is_file():
            return str(exe)
    raise OSError("the rerun command-line tool (package rerun_cli, installed with rerun-sdk) is missing")


def finish(stream: Path, path: Path) -> None:
    """Write the recording ``stream`` (as streamed, without a footer) to ``path`` compacted and with its RRD footer:
    ``rerun rrd optimize`` in a child process, whose memory is given back when it ends, to a temporary name renamed
    into place. OSError when it fails (``path`` is then untouched); Ctrl-C stops the child."""
    exe = rerun_cli()
    env = {**os.environ, "RERUN_ANALYTICS": os.environ.get("RERUN_ANALYTICS", "0")}
    with atomic_path(path) as out:
        r = subprocess.run([exe, "rrd", "optimize", str(stream), "-o", str(out)], env=env, stdin=subprocess.DEVNULL,
                           stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, errors="replace")
        if r.returncode != 0:
            lines = [ln.strip() for ln in r.stderr.splitlines() if ln.strip()]
            why = lines[-1] if lines else f"exit code {r.returncode}"
            raise OSError(f"`rerun rrd optimize` could not finish the recording ({why})")


class RunRecorder:
    """Logs one run: ``log_step(frame, truth, step)`` per frame (Frame, StepTruth, AgentStep), then ``close``.

    path: the recording (RUN.rrd); rig: the stereo rig; lane_lines: (N, 2) world polylines of the road's lane
    lines [m]; tasks: the slot table entries to draw (each with a ``recorder`` part, or None for none);
    options: what is stored of the cameras; duration_s: the run's simulated length [s] if known, for the free space
    checked before anything is written (``space.check_space``); rear_rig: the rear-facing rig (None: the car has
    none), whose left image is stored beside the forward one on frames that have its pair (``Frame.has_rear``). The
    free space is watched through the run: below ``space.RESERVE_BYTES`` the stream is dropped and ``log_step`` raises
    ``space.no_space``. Also a context manager (an exception closes it as partial).
    """

    def __init__(self, path: Path, rig: StereoRig, lane_lines: list[np.ndarray], tasks,
                 options: RecordOptions = RecordOptions(), app_id: str = "percept", duration_s: float | None = None,
                 rear_rig: StereoRig | None = None):
        self.path = Path(path)
        if not self.path.parent.is_dir():
            raise ValueError(f"cannot record to {self.path}: the folder {self.path.parent} does not exist")
        space.check_space(self.path, duration_s, options)
        self.tmp = self.path.with_name(f".{self.path.name}.part")
        self.options = options
        self.parts = [(t.name, resolve_part(t.recorder)) for t in tasks if t.recorder is not None]
        if any(name == "control" for name, _ in self.parts):
            raise ValueError("a task may not be named 'control': the control part records under that name")
        self.parts.append(("control", parts.control))
        self.buffer = ColumnBuffer(TIMELINE)
        self.contexts = {name: PartContext(name, rig, self.buffer, image_scale=options.image_scale, rear_rig=rear_rig)
                         for name, _ in self.parts}
        self.rig = rig
        self.camera = CameraStore(CAMERA, rig, options)
        self.rear_camera = CameraStore(REAR_CAMERA, rear_rig, options, "rear_box_px") if rear_rig else None
        self.closed_as: Path | None = None
        self.failed: OSError | None = None
        self._watched_at = time.monotonic()
        self.tmp.unlink(missing_ok=True)  # left over from a run that was killed
        self.rec = rr.RecordingStream(app_id, batcher_config=rr.ChunkBatcherConfig(**BATCHING))
        # no footer (see the module's docstring)
        self.rec.save(str(self.tmp), default_blueprint=blueprint(self.parts, rear=rear_rig is not None),
                      write_footer=False)
        try:
            self._log_static(lane_lines)
        except BaseException:
            self.rec.disconnect()
            self.tmp.unlink(missing_ok=True)
            raise

    def _log_static(self, lane_lines: list[np.ndarray]) -> None:
        rec = self.rec
        rec.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
        rec.log("world", rr.AnnotationContext([(cid, kind.value, rgb) for kind, (cid, rgb) in KIND_CLASSES.items()]),
                static=True)
        strips = [np.column_stack([p, np.zeros(len(p))]) for p in lane_lines]
        rec.log("world/road", rr.LineStrips3D(strips, colors=[(200, 200, 200)], radii=0.08), static=True)
        for camera in (self.camera, self.rear_camera):
            if camera is not None:
                camera.log_static(rec)
        rec.log(TRAJECTORY, rr.Points3D.from_fields(colors=[TRAJECTORY_RGB], radii=[0.3]), static=True)
        rec.log(f"{EGO}/body", rr.Boxes3D(centers=[[0, 0, EGO_HEIGHT_M / 2]],
                                          sizes=[[EGO_LENGTH_M, EGO_WIDTH_M, EGO_HEIGHT_M]], colors=[TRAJECTORY_RGB]),
                static=True)
        for name, part in self.parts:
            if isinstance(part, Part):
                part.style(rec, self.contexts[name])

    def log_step(self, frame, truth, step) -> None:
        """One frame: ``frame`` (Frame), ``truth`` (StepTruth), ``step`` (AgentStep)."""
        self._watch()
        rec = self.rec
        rec.set_time(TIMELINE, duration=frame.timestamp_s)
        self.buffer.set_time(frame.timestamp_s)
        if self.buffer.held_s() >= COLUMNS_FLUSH_S:
            self.buffer.flush(rec)
        gt = truth.truth
        e = gt.ego
        self.buffer.add(EGO, rr.Transform3D, translation=[[e.x_m, e.y_m, 0.0]],
                        rotation_axis_angle=[rr.RotationAxisAngle(axis=[0, 0, 1], radians=e.yaw_rad)])
        image = self.camera.store(rec, frame.timestamp_s, frame.left)
        rear = self.rear_camera is not None and frame.has_rear and self.rear_camera.store(rec, frame.timestamp_s,
                                                                                           frame.rear_left)
        self._log_objects(gt.objects, image, rear)
        self.buffer.add(TRAJECTORY, rr.Points3D, positions=[[e.x_m, e.y_m, 0.05]])
        for name, part in self.parts:
            ctx = replace(self.contexts[name], image=image, rear_image=rear)
            if name == "control":
                part(rec, ctx, step, step.control, truth)
            else:
                part(rec, ctx, step.estimates.get(name), step.debug.get(name), truth)

    def _watch(self) -> None:
        """Every ``WATCH_S``: stop recording (``_drop``) and raise ``no_space`` when the disk is nearly full; after
        that, every call raises the same error."""
        if self.failed is None and time.monotonic() - self._watched_at >= WATCH_S:
            self._watched_at = time.monotonic()
            free = space.free_bytes(self.tmp.parent)
            if free < space.RESERVE_BYTES:
                self.failed = space.no_space(self.path, f"its disk has filled up ({space.size_text(free)} free); the "
                                                  f"recording was not kept")
                self._drop()
        if self.failed is not None:
            raise self.failed

    def _drop(self) -> None:
        """Abandon the stream without flushing or disconnecting it (either, into a full disk, can block for good):
        the part file is removed, and its space comes back once Rerun's writer lets go of it. The stream is held in
        ``ABANDONED`` and Rerun's exit hook withdrawn: both its finaliser and that hook flush and wait for a writer
        that never returns, so the command line ends the process without them (``cli.common.run_cli``)."""
        self.tmp.unlink(missing_ok=True)
        ABANDONED.append(self.rec)
        rr.unregister_shutdown()

    def _log_objects(self, objects, image: bool, rear: bool) -> None:
        """True boxes: 3D in the vehicle frame (under the ego's transform) and, on each image stored this frame (the
        forward ``image``, the ``rear`` one), 2D on it."""
        if objects:
            # Boxes3D(sizes=s) logs half sizes: float32 s / 2
            self.buffer.add(OBJECTS, rr.Boxes3D, centers=[o.position_m for o in objects],
                            half_sizes=np.asarray([o.size_m for o in objects], np.float32) / 2.0,
                            rotation_axis_angles=[rr.RotationAxisAngle(axis=[0, 0, 1], radians=o.yaw_rad)
                                                  for o in objects],
                            class_ids=[KIND_CLASSES[o.kind][0] for o in objects], show_labels=[False])
        else:
            self.buffer.clear(OBJECTS)
        if image:
            self.camera.log_boxes(self.rec, self.buffer, objects)
        if rear:
            self.rear_camera.log_boxes(self.rec, self.buffer, objects)

    def close(self, complete: bool = True) -> Path:
        """Flush and move the recording into place: ``path`` when ``complete`` (compacted, with its footer:
        ``finish``), else ``RUN.partial.rrd`` beside it (an interrupted or failed run, or one whose end could not be
        written; a finished ``RUN.rrd`` is never touched). Returns where it went; a second call does nothing."""
        if self.closed_as is not None:
            return self.closed_as
        if self.failed is not None:  # dropped by ``_watch``: nothing to keep, nothing to flush
            self.tmp.unlink(missing_ok=True)
            raise self.failed
        target = partial_path(self.path)
        try:
            try:
                self.buffer.flush(self.rec)
                self.rec.flush(timeout_sec=FLUSH_TIMEOUT_S)
            except RuntimeError as e:  # the writer met a full disk between two looks, or hangs
                raise OSError(f"Rerun could not write the end of the stream ({e})") from None
            finally:
                self.rec.disconnect()
            if complete:
                if self.tmp.exists():
                    finish(self.tmp, self.path)
                    self.tmp.unlink()
                target = self.path
        finally:  # Ctrl-C or a full disk while flushing or finishing: the stream is kept as partial
            try:
                if self.tmp.exists():
                    os.replace(self.tmp, target)
            except OSError:  # e.g. a folder in the way: no temporary is left behind, the target is untouched
                self.tmp.unlink(missing_ok=True)
                raise
            self.closed_as = target
        return target

    def __enter__(self) -> "RunRecorder":
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        self.close(complete=exc_type is None)
