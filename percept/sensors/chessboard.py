"""Camera intrinsics from chessboard photos: Zhang's method as OpenCV implements it.

Z. Zhang, "A flexible new technique for camera calibration", PAMI 22(11), 2000: the inner corners of a planar
chessboard are found (``cv2.findChessboardCorners``), refined to sub-pixel accuracy (``cv2.cornerSubPix``, the
saddle point where the gradients are orthogonal to the lines to the corner), and ``cv2.calibrateCamera``
estimates K and the Brown-Conrady distortion (k1, k2, p1, p2, k3) by minimising the reprojection error over all
views (Levenberg-Marquardt). See also Hartley & Zisserman, *Multiple View Geometry*, 2nd ed., sec. 7.4 and 8.8.

The calibration file (JSON) holds fx, fy, cx, cy [px], width, height [px], dist (OpenCV order), rms_px
(RMS reprojection error [px]) and the counts of photos used; ``percept lanes --calib FILE`` reads it.
"""

from __future__ import annotations

import json
import re
from collections import Counter
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Callable, Sequence

import cv2
import numpy as np

from .camera import PinholeCamera

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".ppm", ".pgm", ".webp")
MIN_VIEWS = 3
"""Fewest board views (photos, or stereo pairs) a calibration accepts: fewer leave K undetermined."""
MAX_CORNERS = 100
"""Most inner corners a board side may have (OpenCV's detector is not meant for more)."""


def parse_pattern(text: str) -> tuple[int, int]:
    """'9x6' -> (9, 6): inner corners per row and per column of the chessboard (each at least 2)."""
    m = re.fullmatch(r"\s*(\d+)\s*[xX×]\s*(\d+)\s*", str(text))
    if m is None:
        raise ValueError(f"pattern {text!r} is not COLSxROWS of inner corners, e.g. 9x6")
    cols, rows = int(m.group(1)), int(m.group(2))
    if cols < 2 or rows < 2:
        raise ValueError(f"pattern {text!r} needs at least 2x2 inner corners")
    if cols > MAX_CORNERS or rows > MAX_CORNERS:
        raise ValueError(f"pattern {text!r} has more than {MAX_CORNERS} inner corners a side; count the corners "
                         "where four squares meet, e.g. 9x6")
    return cols, rows


@dataclass(frozen=True)
class CameraCalibration:
    """Intrinsics and lens distortion of one camera.

    fx, fy: focal lengths [px]; cx, cy: principal point [px]; width, height: image size [px];
    dist: distortion coefficients in OpenCV's order (k1, k2, p1, p2, k3) [unitless];
    rms_px: RMS reprojection error over the used photos [px]; images_used: photos of the calibrated size in
    which the board was found; images_found: photos with the board (any size); images_total: photos read;
    pattern: inner corners (cols, rows).
    """

    fx: float
    fy: float
    cx: float
    cy: float
    width: int
    height: int
    dist: tuple[float, ...]
    rms_px: float
    images_used: int = 0
    images_found: int = 0
    images_total: int = 0
    pattern: tuple[int, int] = (9, 6)

    def __post_init__(self) -> None:
        self.camera()  # PinholeCamera validates focal lengths and size

    @property
    def K(self) -> np.ndarray:
        return self.camera().K

    def camera(self) -> PinholeCamera:
        """The pinhole camera of the undistorted images (same K, no distortion)."""
        return PinholeCamera(self.fx, self.fy, self.cx, self.cy, self.width, self.height)

    def undistort(self, image: np.ndarray) -> np.ndarray:
        """Remove lens distortion (cv2.undistort, same K); the image must have the calibrated size."""
        h, w = image.shape[:2]
        if (w, h) != (self.width, self.height):
            raise ValueError(f"image is {w}x{h} but the calibration is for {self.width}x{self.height}; "
                             "calibrate with photos of the same camera and resolution")
        return cv2.undistort(image, self.K, np.asarray(self.dist, dtype=np.float64))

    def to_dict(self) -> dict:
        d = asdict(self)
        d["dist"] = list(self.dist)
        d["pattern"] = f"{self.pattern[0]}x{self.pattern[1]}"
        return d

    @classmethod
    def from_dict(cls, d: dict) -> "CameraCalibration":
        return cls(float(d["fx"]), float(d["fy"]), float(d["cx"]), float(d["cy"]), int(d["width"]),
                   int(d["height"]), tuple(float(k) for k in d["dist"]), float(d.get("rms_px", float("nan"))),
                   int(d.get("images_used", 0)), int(d.get("images_found", 0)), int(d.get("images_total", 0)),
                   parse_pattern(d.get("pattern", "9x6")))

    def save(self, path: Path) -> None:
        Path(path).write_text(json.dumps(self.to_dict(), indent=2))

    @classmethod
    def load(cls, path: Path) -> "CameraCalibration":
        try:
            return cls.from_dict(json.loads(Path(path).read_text()))
        except FileNotFoundError:
            raise ValueError(f"calibration file {path} does not exist; make one with `percept calibrate DIR`") from None
        except (OSError, UnicodeDecodeError) as e:
            raise ValueError(f"cannot read calibration file {path} ({e})") from None
        except (KeyError, TypeError, ValueError, AttributeError) as e:
            raise ValueError(f"{path} is not a percept calibration file ({e}); "
                             "make one with `percept calibrate DIR`") from None


def chessboard_images(folder: Path) -> list[Path]:
    """Image files directly in ``folder``, sorted by name; ValueError when there are none."""
    folder = Path(folder)
    if not folder.is_dir():
        raise ValueError(f"{folder} is not a folder of chessboard photos")
    files = sorted(p for p in folder.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES and p.is_file())
    if not files:
        raise ValueError(f"{folder} holds no images ({', '.join(IMAGE_SUFFIXES)})")
    return files


def find_corners(gray: np.ndarray, pattern: tuple[int, int]) -> np.ndarray | None:
    """Inner chessboard corners (N, 1, 2) float32 (u, v) [px] refined to sub-pixel, or None when not found."""
    flags = cv2.CALIB_CB_ADAPTIVE_THRESH | cv2.CALIB_CB_NORMALIZE_IMAGE
    ok, corners = cv2.findChessboardCorners(gray, pattern, flags=flags)
    if not ok:
        return None
    # sub-pixel: minimise sum_p (grad I(p) . (q - p))^2 over an 11x11 window around each corner q
    crit = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 30, 1e-3)
    return cv2.cornerSubPix(gray, corners, (11, 11), (-1, -1), crit)


def board_points(pattern: tuple[int, int], square_m: float = 1.0) -> np.ndarray:
    """Board points (cols * rows, 3) float32: the inner-corner grid (X, Y, 0) in metres (or squares)."""
    cols, rows = pattern
    obj = np.zeros((cols * rows, 3), np.float32)
    obj[:, :2] = np.mgrid[0:cols, 0:rows].T.reshape(-1, 2) * square_m
    return obj


def calibrate_points(corners: list[np.ndarray], size: tuple[int, int], pattern: tuple[int, int],
                     square_m: float = 1.0, found: int = 0, total: int = 0) -> CameraCalibration:
    """Zhang (2000) from the corners (each (N, 1, 2) [px]) of photos of one size (width, height)."""
    obj = board_points(pattern, square_m)
    # minimise sum_i sum_j || x_ij - pi(K, dist, R_i, t_i, X_j) ||^2 (Zhang 2000, eq. 10 with distortion)
    rms, K, dist, _, _ = cv2.calibrateCamera([obj] * len(corners), corners, size, None, None)
    return CameraCalibration(float(K[0, 0]), float(K[1, 1]), float(K[0, 2]), float(K[1, 2]), int(size[0]),
                             int(size[1]), tuple(float(k) for k in np.ravel(dist)), float(rms), len(corners),
                             found or len(corners), total or len(corners), pattern)


def calibrate_chessboards(paths: Sequence[Path], pattern: tuple[int, int], square_m: float = 1.0,
                          progress: Callable[[Path, bool], None] | None = None) -> CameraCalibration:
    """Zhang (2000) calibration from photos of a chessboard with ``pattern`` inner corners (cols, rows).

    square_m scales the board (it changes no intrinsic). Only photos of the most common size are used: a photo of
    another size (e.g. 1281x721 among 1280x720) is a resized or cropped copy whose pixels do not share the
    intrinsics, and keeping such photos raises the RMS error (udacity camera_cal: 1.00 px with, 0.85 px without).
    Raises ValueError when no photo is readable or the board is found in none.
    """
    cols, rows = pattern
    found: list[tuple[tuple[int, int], np.ndarray]] = []
    readable = 0
    for p in paths:
        img = cv2.imread(str(p), cv2.IMREAD_GRAYSCALE)
        corners = None
        if img is not None:
            readable += 1
            corners = find_corners(img, pattern)
            if corners is not None:
                found.append(((img.shape[1], img.shape[0]), corners))
        if progress is not None:
            progress(Path(p), corners is not None)
    if readable == 0:
        raise ValueError("none of the photos could be read as an image")
    if not found:
        raise ValueError(f"no {cols}x{rows} chessboard found in any of {readable} photos; "
                         "check --pattern (inner corners, e.g. 9x6 for a 10x7-square board)")
    size, views = Counter(s for s, _ in found).most_common(1)[0]
    if views < MIN_VIEWS:
        raise ValueError(f"the {cols}x{rows} board was found in only {views} photo(s) of one size; at least "
                         f"{MIN_VIEWS} views at different angles are needed")
    return calibrate_points([c for s, c in found if s == size], size, (cols, rows), square_m, len(found), readable)
