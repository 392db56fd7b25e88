"""Writing rendered runs to disk: stereo PNGs, depth, ground truth JSON, camera and landmark files."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Callable

import cv2
import numpy as np

from percept.sensors import Frame

from .ground_truth import GroundTruth
from .world import SimWorld


def prepare_out_dir(out: Path) -> Path:
    """Create ``out`` (and parents) and check it is writable; ValueError saying what is wrong otherwise."""
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ValueError(f"output path {out} exists and is not a folder")
    try:
        out.mkdir(parents=True, exist_ok=True)
        probe = out / ".percept-write-test"
        probe.write_text("")
        probe.unlink()
    except OSError as e:
        raise ValueError(f"cannot write to {out}: {e.strerror or e}") from None
    return out


def write_frame(out: Path, i: int, frame: Frame, gt: GroundTruth) -> None:
    """``{i:06d}_left.png``, ``_right.png`` (absent for a dropped frame), ``_depth.npy`` (float32 m, inf sky),
    ``_gt.json``."""
    stem = out / f"{i:06d}"
    if not frame.dropped:
        cv2.imwrite(f"{stem}_left.png", frame.left)
        cv2.imwrite(f"{stem}_right.png", frame.right)
    np.save(f"{stem}_depth.npy", gt.depth_m.astype(np.float32))
    d = gt.to_dict()
    d["frame"] = i
    d["dropped"] = frame.dropped
    d["sensors"] = {"imu": {"accel_mps2": frame.imu.accel_mps2.tolist(), "gyro_rps": frame.imu.gyro_rps.tolist()},
                    "wheel_speed_mps": frame.wheel_speed_mps}
    Path(f"{stem}_gt.json").write_text(json.dumps(d, indent=1))


def render_run(world: SimWorld, frames: int, out: Path, progress: Callable[[], None] | None = None) -> None:
    """Render ``frames`` consecutive frames of ``world`` into ``out`` with camera.json (and landmarks.json)."""
    if frames < 1:
        raise ValueError(f"--frames must be at least 1, got {frames}")
    out = prepare_out_dir(out)
    world.cfg.rig.save(out / "camera.json")
    landmarks = world.landmark_map()
    if len(landmarks):
        (out / "landmarks.json").write_text(json.dumps(landmarks.to_dict(), indent=1))
    for i in range(frames):
        frame, gt = world.observe()
        write_frame(out, i, frame, gt)
        if progress:
            progress()
        if i + 1 < frames:
            world.step()
