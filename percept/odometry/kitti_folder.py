"""A KITTI-layout odometry folder: its images, calibration, optional ground-truth poses and timestamps.

Layout (KITTI odometry devkit, ``sequences/XX/``)::

    DIR/image_0/ or DIR/image_l/   left images, sorted by name
    DIR/image_1/ or DIR/image_r/   right images (optional: stereo)
    DIR/calib.txt                  "P0: 12 numbers" and "P1: 12 numbers" (row-major 3x4 projection matrices of the
                                   rectified cameras; other lines such as "P2:", "Tr:" are ignored). Lines of 12
                                   numbers without a name are taken as P0, P1, ... in order.
    DIR/poses.txt                  optional: one row-major 3x4 world-from-camera pose per image
    DIR/times.txt                  optional: one timestamp [s] per image

For a rectified pair P1 = K [I | (-b, 0, 0)], so P1[0, 3] = -fx b gives the baseline b (Geiger et al. 2013,
"Vision meets robotics: the KITTI dataset", IJRR, sec. IV.B).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import Optional

import cv2
import numpy as np

from percept.sensors.footage import decode_image, list_images

from .trajectory_io import read_kitti_poses

LEFT_NAMES = ("image_0", "image_l")
RIGHT_NAMES = ("image_1", "image_r")
_PNG = b"\x89PNG\r\n\x1a\n"
_LABEL = re.compile(r"^\s*([A-Za-z_][\w]*)\s*:(.*)$")


@dataclass(frozen=True)
class KittiFolder:
    """What a KITTI-layout folder holds.

    root: the folder; left: left image paths (N,), sorted; right: right image paths (N,) or None (monocular);
    image_size: (width, height) [px] of every image; P0, P1: (3, 4) projection matrices of the left and right
    camera [px] (P1 None without one); K: (3, 3) intrinsics of the left camera [px]; baseline_m: stereo baseline
    [m] from P1, or None; poses: (N, 4, 4) ground-truth world-from-camera poses [m] or None; timestamps_s: (N,)
    from times.txt [s] or None.
    """

    root: Path
    left: tuple[Path, ...]
    right: Optional[tuple[Path, ...]]
    image_size: tuple[int, int]
    P0: np.ndarray
    P1: Optional[np.ndarray]
    K: np.ndarray
    baseline_m: Optional[float]
    poses: Optional[np.ndarray]
    timestamps_s: Optional[np.ndarray] = None

    @property
    def stereo(self) -> bool:
        """Both cameras are there (and the baseline is known)."""
        return self.right is not None

    def __len__(self) -> int:
        return len(self.left)


def read_calib(path: Path) -> dict[str, np.ndarray]:
    """Projection matrices (3, 4) of a KITTI calib.txt by name ("P0", "P1", ...); ValueError for a missing file,
    or for a P line that is not 12 finite numbers."""
    if not path.is_file():
        raise ValueError(f"{path} is missing; a KITTI folder needs calib.txt with the line 'P0: <12 numbers>'")
    found: dict[str, np.ndarray] = {}
    unnamed = 0
    for k, line in enumerate(path.read_text(encoding="utf-8", errors="replace").splitlines(), start=1):
        if not line.strip():
            continue
        m = _LABEL.match(line)
        name, values = (m.group(1), m.group(2)) if m else (f"P{unnamed}", line)
        unnamed += m is None
        if not re.fullmatch(r"P\d", name):
            continue
        try:
            P = np.array([float(x) for x in values.split()])
        except ValueError:
            P = np.zeros(0)
        if P.size != 12 or not np.all(np.isfinite(P)):
            raise ValueError(f"{path} line {k}: {name} must be 12 finite numbers (a row-major 3x4 projection matrix)")
        found[name] = P.reshape(3, 4)
    return found


def _image_size(path: Path) -> tuple[int, int]:
    """(width, height) [px]: from a PNG's IHDR header (bytes 16-24), else by decoding the image."""
    with open(path, "rb") as f:
        head = f.read(24)
    if head[:8] == _PNG and head[12:16] == b"IHDR":
        return int.from_bytes(head[16:20], "big"), int.from_bytes(head[20:24], "big")
    img = decode_image(path, cv2.IMREAD_UNCHANGED)
    return img.shape[1], img.shape[0]


def _one_size(files: list[Path], root: Path) -> tuple[int, int]:
    """The size every image in ``files`` shares; ValueError naming the first that differs."""
    size = _image_size(files[0])
    for p in files[1:]:
        s = _image_size(p)
        if s != size:
            raise ValueError(f"{p.relative_to(root)} is {s[0]}x{s[1]} px but {files[0].relative_to(root)} is "
                             f"{size[0]}x{size[1]}; every image of the sequence must have one size")
    return size


def _sub(root: Path, names: tuple[str, ...]) -> Optional[Path]:
    return next((root / n for n in names if (root / n).is_dir()), None)


def _baseline(P0: np.ndarray, P1: Optional[np.ndarray]) -> Optional[float]:
    if P1 is None or P1[0, 0] <= 0:
        return None
    # P1[0, 3] - P0[0, 3] = -fx b
    b = -(P1[0, 3] - P0[0, 3]) / P1[0, 0]
    return float(b) if np.isfinite(b) and b > 0 else None


def _per_image(path: Path, n: int, what: str) -> bool:
    """Whether the optional file exists; ValueError when its count of lines is not the number of images."""
    if not path.is_file():
        return False
    lines = [s for s in path.read_text(encoding="utf-8", errors="replace").splitlines()
             if s.strip() and not s.lstrip().startswith("#")]
    if len(lines) != n:
        raise ValueError(f"{path} has {len(lines)} {what} but there are {n} images; give one line per image")
    return True


def load_kitti_folder(root: Path | str) -> KittiFolder:
    """Read a KITTI-layout folder (see the module docstring); one ValueError per problem: no such folder, no
    image folder or no images, calib.txt missing or without P0, images of mixed sizes, left and right counts that
    differ, a right folder without a P1 baseline, poses.txt or times.txt with a line count other than the number
    of images or a line that is not numbers."""
    root = Path(root)
    if not root.is_dir():
        raise ValueError(f"{root} is not a folder; give a KITTI-layout folder (image_0/ or image_l/, calib.txt)")
    left_dir, right_dir = _sub(root, LEFT_NAMES), _sub(root, RIGHT_NAMES)
    if left_dir is None:
        raise ValueError(f"{root} has no image_0/ or image_l/ folder of left images")
    left = list_images(left_dir)
    right = list_images(right_dir) if right_dir is not None else None
    if right is not None and len(right) != len(left):
        raise ValueError(f"{right_dir.name}/ has {len(right)} images but {left_dir.name}/ has {len(left)}; "
                         "give one right image per left image")
    calib = read_calib(root / "calib.txt")
    if "P0" not in calib:
        raise ValueError(f"{root / 'calib.txt'} has no P0 line ('P0: <12 numbers>', the left camera's projection)")
    P0, P1 = calib["P0"], calib.get("P1")
    baseline = _baseline(P0, P1)
    if right is not None and baseline is None:
        raise ValueError(f"{root} has right images ({right_dir.name}/) but calib.txt gives no stereo baseline: "
                         "add 'P1: <12 numbers>' with P1[0,3] = -fx * baseline (negative)")
    size = _one_size(left + (right or []), root)
    poses = read_kitti_poses(root / "poses.txt") if _per_image(root / "poses.txt", len(left), "poses") else None
    times = None
    if _per_image(root / "times.txt", len(left), "timestamps"):
        try:
            times = np.loadtxt(root / "times.txt", dtype=np.float64, ndmin=1)
        except ValueError:
            raise ValueError(f"{root / 'times.txt'} must hold one number (seconds) per line") from None
    return KittiFolder(root, tuple(left), None if right is None else tuple(right), size, P0, P1,
                       P0[:, :3].copy(), baseline, poses, times)
