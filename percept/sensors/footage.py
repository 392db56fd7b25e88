"""Recorded footage: which files a source holds, reading images and videos, and removing lens distortion.

Every footage command (``percept lanes``, ``stereo``, ``detect``, ``odometry``, ``calibrate``) reads through here,
so that a missing, unreadable or truncated file gets the same one-line ``ValueError`` everywhere.

A truncated JPEG decodes without an error in OpenCV (libjpeg fills the missing rows with grey and only warns),
so ``read_image`` walks the file's structure first: a JPEG's marker segments up to its end-of-image marker
(FFD9), a PNG's chunks up to its IEND chunk (ITU-T T.81 annex B; PNG spec, ISO/IEC 15948 sec. 5).
A video that ends before the frame count its header declares is reported by ``VideoReader.ended_early``.
"""

from __future__ import annotations

import math
import os
from enum import Enum
from pathlib import Path
from typing import Iterator, Sequence

import cv2
import numpy as np

from .camera import PinholeCamera

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".ppm", ".pgm", ".webp")
VIDEO_SUFFIXES = (".mp4", ".avi", ".mov", ".mkv", ".m4v", ".mpg", ".mpeg", ".webm")
_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


class FootageKind(str, Enum):
    """What a footage source is: still images (one file or a folder of them) or one video."""

    IMAGES = "images"
    VIDEO = "video"


def list_images(folder: Path) -> list[Path]:
    """Image files directly in ``folder`` (hidden files left out), sorted by name; ValueError when ``folder`` is
    not a folder or holds no image."""
    folder = Path(folder)
    if not folder.is_dir():
        raise ValueError(f"{folder} is not a folder")
    files = sorted((p for p in folder.iterdir()
                    if p.suffix.lower() in IMAGE_SUFFIXES and not p.name.startswith(".") and p.is_file()),
                   key=lambda p: p.name)
    if not files:
        raise ValueError(f"{folder} holds no images ({', '.join(IMAGE_SUFFIXES)})")
    return files


def list_footage(path: Path) -> tuple[FootageKind, list[Path]]:
    """(VIDEO, [file]) or (IMAGES, files) for an image, a video or a folder of images (sorted by name);
    ValueError for a missing path, an unknown suffix or a folder without images."""
    path = Path(path)
    if path.is_dir():
        return FootageKind.IMAGES, list_images(path)
    if not path.exists():
        raise ValueError(f"{path} does not exist; give an image, a video or a folder of images")
    if path.suffix.lower() in VIDEO_SUFFIXES:
        return FootageKind.VIDEO, [path]
    if path.suffix.lower() in IMAGE_SUFFIXES:
        return FootageKind.IMAGES, [path]
    raise ValueError(f"{path} is neither an image ({', '.join(IMAGE_SUFFIXES)}) "
                     f"nor a video ({', '.join(VIDEO_SUFFIXES)})")


def _entropy_end(data: bytes, i: int) -> int:
    """Index of the first marker after the entropy-coded data starting at ``i`` (FF00 is a stuffed FF byte,
    FFD0..FFD7 are restart markers, FFFF fill), or -1 when the data runs to the end of the file."""
    n = len(data)
    while True:
        i = data.find(b"\xff", i)
        if i < 0 or i + 1 >= n:
            return -1
        nxt = data[i + 1]
        if nxt == 0x00 or 0xD0 <= nxt <= 0xD7:
            i += 2
        elif nxt == 0xFF:
            i += 1
        else:
            return i


def _jpeg_complete(data: bytes) -> bool:
    """True when the JPEG marker stream reaches its end-of-image marker FFD9: segments are skipped by their
    length fields (so an EXIF thumbnail's FFD9 does not count), scans by searching for the next marker; bytes
    after FFD9 (appended metadata) are allowed."""
    i, n = 2, len(data)
    while i + 1 < n:
        if data[i] != 0xFF:
            # extraneous bytes between segments: libjpeg skips them to the next marker, and so do we
            i = data.find(b"\xff", i)
            if i < 0:
                return False
            continue
        marker = data[i + 1]
        if marker == 0xD9:
            return True
        if marker == 0xFF:
            i += 1
            continue
        if 0xD0 <= marker <= 0xD8 or marker == 0x01:
            i += 2
            continue
        if i + 4 > n:
            return False
        i += 2 + int.from_bytes(data[i + 2:i + 4], "big")
        if marker == 0xDA:
            i = _entropy_end(data, i)
            if i < 0:
                return False
    return False


def _png_complete(data: bytes) -> bool:
    """True when the PNG chunk sequence (length, type, data, CRC) reaches a whole IEND chunk."""
    i, n = len(_PNG_SIGNATURE), len(data)
    while i + 8 <= n:
        length = int.from_bytes(data[i:i + 4], "big")
        kind = data[i + 4:i + 8]
        i += 12 + length
        if kind == b"IEND":
            return i <= n
    return False


def truncation(data: bytes) -> str | None:
    """Why the bytes of a JPEG or PNG file are cut short (the missing end marker), or None when they are whole
    or of another format."""
    if data[:2] == b"\xff\xd8" and not _jpeg_complete(data):
        return "no JPEG end-of-image marker FFD9"
    if data[:8] == _PNG_SIGNATURE and not _png_complete(data):
        return "no PNG IEND chunk"
    return None


def decode_image(path: Path, flags: int) -> np.ndarray:
    """The image in ``path`` decoded with the ``cv2.IMREAD_*`` ``flags`` (EXIF orientation applied, as
    cv2.imread does); ValueError "cannot read PATH as an image ..." when the file is missing, empty, unreadable,
    a truncated JPEG or PNG, or anything OpenCV cannot decode."""
    path = Path(path)
    if not path.exists():
        raise ValueError(f"{path} does not exist")
    if path.is_dir():
        raise ValueError(f"{path} is a folder, not an image")
    try:
        data = path.read_bytes()
    except OSError as e:
        raise ValueError(f"cannot read {path} ({e.strerror or e})") from None
    if not data:
        raise ValueError(f"cannot read {path} as an image: the file is empty (0 bytes); copy it again")
    why = truncation(data)
    if why is not None:
        raise ValueError(f"cannot read {path} as an image: the file is truncated ({why}); copy it again")
    try:
        img = cv2.imdecode(np.frombuffer(data, np.uint8), flags)
    except cv2.error:
        img = None
    if img is None or img.size == 0:
        raise ValueError(f"cannot read {path} as an image (not an image file, or a format this OpenCV cannot decode)")
    return img


def read_image(path: Path, gray: bool = False) -> np.ndarray:
    """A BGR (H, W, 3) or, with ``gray``, a (H, W) uint8 image; ValueError as ``decode_image``."""
    return decode_image(path, cv2.IMREAD_GRAYSCALE if gray else cv2.IMREAD_COLOR)


class VideoReader:
    """The frames of a video file, read once in order: ``for frame in reader`` yields BGR (H, W, 3) uint8 images,
    at most ``max_frames`` of them.

    fps [1/s] (25 when the file gives none that is plausible); declared_frames: the frame count the container
    declares (None when it declares none; for some containers it is an estimate from the duration); size:
    (width, height) [px]; frames_read: frames yielded so far. Once the frames run out, ``ended_early`` tells
    whether fewer came than the header declares (up to max_frames): a truncated or damaged file. Opening reads
    the first frame, so an unreadable video fails here, with a ValueError.
    """

    def __init__(self, path: Path, max_frames: int | None = None):
        path = Path(path)
        if not path.is_file():
            raise ValueError(f"{path} does not exist" if not path.exists() else f"{path} is not a video file")
        if max_frames is not None and max_frames < 1:
            raise ValueError(f"max_frames must be at least 1, got {max_frames}")
        # FFmpeg's own log lines (e.g. "moov atom not found") would repeat our one-line error
        os.environ.setdefault("OPENCV_FFMPEG_LOGLEVEL", "-8")
        cap = cv2.VideoCapture(str(path))
        ok, first = cap.read() if cap.isOpened() else (False, None)
        if not ok or first is None:
            cap.release()
            raise ValueError(f"cannot read {path} as a video (not a video file, damaged, or a codec this OpenCV "
                             "build lacks)")
        fps = float(cap.get(cv2.CAP_PROP_FPS))
        n = int(cap.get(cv2.CAP_PROP_FRAME_COUNT))
        self.path, self.max_frames = path, max_frames
        self.fps = fps if math.isfinite(fps) and 0 < fps < 1000 else 25.0
        self.declared_frames: int | None = n if n > 0 else None
        self.size = (int(first.shape[1]), int(first.shape[0]))
        self.frames_read = 0
        self._cap, self._first, self._ran_out = cap, first, False

    @property
    def expected_frames(self) -> int | None:
        """Frames the iteration should yield: the declared count, capped at max_frames; None when undeclared."""
        if self.declared_frames is None:
            return None
        return min(self.declared_frames, self.max_frames) if self.max_frames is not None else self.declared_frames

    @property
    def ended_early(self) -> bool:
        """True once the decoder has run out before ``expected_frames`` frames were read."""
        expected = self.expected_frames
        return self._ran_out and expected is not None and self.frames_read < expected

    def __iter__(self) -> Iterator[np.ndarray]:
        img, self._first = self._first, None
        try:
            while img is not None and (self.max_frames is None or self.frames_read < self.max_frames):
                self.frames_read += 1
                yield img
                ok, img = self._cap.read()
                if not ok:
                    img, self._ran_out = None, True
        finally:
            self.close()

    def close(self) -> None:
        self._cap.release()

    def __enter__(self) -> "VideoReader":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def open_video(path: Path, max_frames: int | None = None) -> VideoReader:
    """A ``VideoReader`` over ``path`` (at most ``max_frames`` frames); ValueError when it cannot be read."""
    return VideoReader(path, max_frames)


class Undistorter:
    """Removes the lens distortion of one camera from each of its frames, keeping its K: the remap tables
    (``cv2.initUndistortRectifyMap``) are computed once, each frame is one bilinear ``cv2.remap``.

    camera: the intrinsics (and image size) of the distorted images; dist: distortion coefficients in OpenCV's
    order (k1, k2, p1, p2[, k3, ...]). Hartley & Zisserman, *Multiple View Geometry*, 2nd ed., sec. 7.4.
    """

    def __init__(self, camera: PinholeCamera, dist: Sequence[float]):
        self.camera = camera
        self.dist = np.asarray(dist, dtype=np.float64)
        size = (camera.width, camera.height)
        # undistorted pixel p (same K) is read from the distorted image at K d(K^-1 p), d the Brown-Conrady model
        self._maps = cv2.initUndistortRectifyMap(camera.K, self.dist, None, camera.K, size, cv2.CV_16SC2)

    def check_size(self, image: np.ndarray) -> None:
        """ValueError unless ``image`` has the calibrated size."""
        h, w = image.shape[:2]
        cam = self.camera
        if (w, h) != (cam.width, cam.height):
            raise ValueError(f"image is {w}x{h} but the calibration is for {cam.width}x{cam.height}; "
                             "calibrate with photos of the same camera and resolution")

    def __call__(self, image: np.ndarray) -> np.ndarray:
        """The undistorted image, same size, dtype and channels as ``image``."""
        self.check_size(image)
        return cv2.remap(image, *self._maps, cv2.INTER_LINEAR)
