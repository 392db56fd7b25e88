"""Writing rendered runs to disk: stereo PNGs, depth, ground truth JSON, camera and landmark files.

Every file goes through ``percept.outputs``: a frame's files (images, depth, ground truth) are written to
temporaries and renamed together, so each frame on disk is complete or absent, whatever stops the run (an error,
a full disk, Ctrl-C). A folder holds one run: ``prepare_out_dir`` refuses a folder with files unless told to clear
it, and then removes only files a render writes.
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Callable

import numpy as np

from percept.outputs import npy_bytes, png_bytes, write_files_atomic, write_json_atomic
from percept.sensors import Frame

from .ground_truth import GroundTruth
from .world import SimWorld

RENDER_FILE = re.compile(r"\d{6}_((rear_)?left\.png|(rear_)?right\.png|depth\.npy|gt\.json)|(rear_)?camera\.json"
                         r"|landmarks\.json|\.(\d{6}_\w+|(rear_)?camera|landmarks)\.\w+\.tmp\.\w+")
"""Names of the files a render writes (and of its temporaries, left by a killed process)."""


def prepare_out_dir(out: Path, force: bool = False) -> Path:
    """Create ``out`` (and parents) and check it is writable. A folder with files is refused (a render must not mix
    with another one) unless ``force``: then the files of an earlier render are removed, and a file that a render
    does not write still refuses the folder. ValueError saying what is wrong and what to do otherwise."""
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ValueError(f"output path {out} exists and is not a folder; give a folder path")
    if out.is_dir() and (found := sorted(p.name for p in out.iterdir())):
        foreign = [n for n in found if not RENDER_FILE.fullmatch(n)]
        if foreign:
            raise ValueError(f"{out} holds files that percept render did not write (e.g. {foreign[0]}); "
                             "choose an empty or new folder")
        if not force:
            raise ValueError(f"{out} already holds a render ({len(found)} files); choose a new folder, or --force "
                             "to replace it")
        for name in found:
            (out / name).unlink()
    try:
        out.mkdir(parents=True, exist_ok=True)
        probe = out / ".percept-write-test"
        probe.write_text("")
        probe.unlink()
    except OSError as e:
        raise ValueError(f"cannot write to {out}: {e.strerror or e}; choose a folder you can write to") from None
    return out


def write_frame(out: Path, i: int, frame: Frame, gt: GroundTruth) -> None:
    """``{i:06d}_left.png``, ``_right.png`` (and ``_rear_left.png``, ``_rear_right.png`` with a rear rig; absent for
    a dropped frame), ``_depth.npy`` (float32 m, inf sky), ``_gt.json``: all of them or none."""
    stem = f"{i:06d}"
    d = gt.to_dict()
    d["frame"] = i
    d["dropped"] = frame.dropped
    d["sensors"] = {"imu": {"accel_mps2": frame.imu.accel_mps2.tolist(), "gyro_rps": frame.imu.gyro_rps.tolist()},
                    "wheel_speed_mps": frame.wheel_speed_mps}
    files = {} if frame.dropped else {out / f"{stem}_left.png": png_bytes(frame.left),
                                      out / f"{stem}_right.png": png_bytes(frame.right)}
    if frame.has_rear:
        files.update({out / f"{stem}_rear_left.png": png_bytes(frame.rear_left),
                      out / f"{stem}_rear_right.png": png_bytes(frame.rear_right)})
    files[out / f"{stem}_depth.npy"] = npy_bytes(gt.depth_m.astype(np.float32))
    # the ground truth last: a reader that finds it finds the whole frame
    files[out / f"{stem}_gt.json"] = json.dumps(d, indent=1).encode()
    write_files_atomic(files)


def render_run(world: SimWorld, frames: int, out: Path, progress: Callable[[], None] | None = None) -> None:
    """Render ``frames`` consecutive frames of ``world`` into ``out`` (made ready by ``prepare_out_dir``) with
    camera.json (rear_camera.json with a rear rig, landmarks.json with signs); ``written`` counts the frames when
    stopped early."""
    if frames < 1:
        raise ValueError(f"--frames must be at least 1, got {frames}")
    world.cfg.rig.save(out / "camera.json")
    if world.cfg.rear_rig is not None:
        world.cfg.rear_rig.save(out / "rear_camera.json")
    landmarks = world.landmark_map()
    if len(landmarks):
        write_json_atomic(out / "landmarks.json", landmarks.to_dict(), indent=1)
    for i in range(frames):
        frame, gt = world.observe()
        write_frame(out, i, frame, gt)
        if progress:
            progress()
        if i + 1 < frames:
            world.step()


def written(out: Path) -> int:
    """Complete frames in a render folder (each has its ground truth file, renamed last)."""
    return sum(1 for _ in Path(out).glob("[0-9]" * 6 + "_gt.json"))
