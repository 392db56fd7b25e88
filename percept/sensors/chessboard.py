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
import math
import re
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Sequence

import cv2
import numpy as np

from percept.outputs import write_json_atomic

from .camera import PinholeCamera
from .footage import Undistorter, list_images, read_image

MIN_VIEWS = 3
"""Fewest board views (photos, or stereo pairs) a calibration accepts: fewer leave K undetermined."""
MAX_CORNERS = 100
"""Most inner corners a board side may have (OpenCV's detector is not meant for more)."""


def parse_pattern(text: str) -> tuple[int, int]:
    """'9x6' -> (9, 6): inner corners per row and per column of the chessboard (each at least 3)."""
    m = re.fullmatch(r"\s*(\d+)\s*[xX×]\s*(\d+)\s*", str(text))
    if m is None:
        raise ValueError(f"pattern {text!r} is not COLSxROWS of inner corners, e.g. 9x6")
    cols, rows = int(m.group(1)), int(m.group(2))
    if cols > MAX_CORNERS or rows > MAX_CORNERS:
        raise ValueError(f"pattern {text!r} has more than {MAX_CORNERS} inner corners a side; count the corners "
                         "where four squares meet, e.g. 9x6")
    if cols < 3 or rows < 3:
        raise ValueError(f"pattern {text!r} needs at least 3x3 inner corners (OpenCV finds no smaller board); "
                         "count the corners where four squares meet, e.g. 9x6")
    return cols, rows


@dataclass(frozen=True)
class CameraCalibration:
    """Intrinsics and lens distortion of one camera.

    camera: the pinhole camera (fx, fy, cx, cy, width, height [px]) of the undistorted images, which keep the
    same K; dist: distortion coefficients in OpenCV's order (k1, k2, p1, p2, k3) [unitless]; rms_px: RMS
    reprojection error over the used photos [px]; images_used: photos of the calibrated size in which the board
    was found; images_found: photos with the board (any size); images_total: photos read; pattern: inner
    corners (cols, rows).
    """

    camera: PinholeCamera
    dist: tuple[float, ...]
    rms_px: float
    images_used: int = 0
    images_found: int = 0
    images_total: int = 0
    pattern: tuple[int, int] = (9, 6)

    def __post_init__(self) -> None:
        if len(self.dist) not in (4, 5, 8, 12, 14) or not all(math.isfinite(k) for k in self.dist):
            raise ValueError(f"distortion {list(self.dist)} is not 4, 5, 8, 12 or 14 finite coefficients")

    @property
    def K(self) -> np.ndarray:
        return self.camera.K

    def undistorter(self) -> Undistorter:
        """Undistorts frames of the calibrated size (maps computed once): for a video or a folder of images."""
        return Undistorter(self.camera, self.dist)

    def undistort(self, image: np.ndarray) -> np.ndarray:
        """Remove lens distortion from one image of the calibrated size (same K); ValueError for another size."""
        return self.undistorter()(image)

    def to_dict(self) -> dict:
        """The flat calibration file: fx, fy, cx, cy, width, height, dist, rms_px, counts, pattern 'COLSxROWS'."""
        return {**self.camera.to_dict(), "dist": list(self.dist), "rms_px": self.rms_px,
                "images_used": self.images_used, "images_found": self.images_found,
                "images_total": self.images_total, "pattern": f"{self.pattern[0]}x{self.pattern[1]}"}

    @classmethod
    def from_dict(cls, d: dict) -> "CameraCalibration":
        camera = PinholeCamera(float(d["fx"]), float(d["fy"]), float(d["cx"]), float(d["cy"]), int(d["width"]),
                               int(d["height"]))
        return cls(camera, tuple(float(k) for k in d["dist"]), float(d.get("rms_px", float("nan"))),
                   int(d.get("images_used", 0)), int(d.get("images_found", 0)), int(d.get("images_total", 0)),
                   parse_pattern(d.get("pattern", "9x6")))

    def save(self, path: Path) -> None:
        write_json_atomic(path, self.to_dict())

    @classmethod
    def load(cls, path: Path) -> "CameraCalibration":
        """The calibration ``percept calibrate`` wrote to ``path``; ValueError naming what is wrong otherwise."""
        not_ours = f"{path} is not a percept calibration file ({{}}); make one with `percept calibrate DIR`"
        try:
            d = json.loads(Path(path).read_text())
        except FileNotFoundError:
            raise ValueError(f"calibration file {path} does not exist; make one with `percept calibrate DIR`") from None
        except IsADirectoryError:
            raise ValueError(f"{path} is a folder; give the calibration file `percept calibrate` wrote") from None
        except (OSError, UnicodeDecodeError) as e:
            raise ValueError(f"cannot read calibration file {path} ({e})") from None
        except ValueError as e:
            raise ValueError(not_ours.format(e)) from None
        if isinstance(d, dict) and {"left", "right"} <= d.keys():
            raise ValueError(f"{path} calibrates a stereo rig; give one camera's, made by `percept calibrate DIR` "
                             "without --stereo")
        try:
            return cls.from_dict(d)
        except (KeyError, TypeError, ValueError, AttributeError) as e:
            raise ValueError(not_ours.format(e)) from None


def chessboard_images(folder: Path) -> list[Path]:
    """Image files directly in ``folder``, sorted by name; ValueError when there are none."""
    if not Path(folder).is_dir():
        raise ValueError(f"{folder} is not a folder of chessboard photos")
    return list_images(folder)


def read_gray(path: Path, skipped: Callable[[Path, str], None] | None = None) -> np.ndarray | None:
    """The photo as a grey image, or None when it cannot be read (missing, empty, truncated, not an image), after
    telling ``skipped(path, why)`` why."""
    try:
        return read_image(path, gray=True)
    except ValueError as e:
        if skipped is not None:
            skipped(Path(path), str(e))
        return None


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
    camera = PinholeCamera(float(K[0, 0]), float(K[1, 1]), float(K[0, 2]), float(K[1, 2]), int(size[0]), int(size[1]))
    return CameraCalibration(camera, tuple(float(k) for k in np.ravel(dist)), float(rms), len(corners),
                             found or len(corners), total or len(corners), pattern)


def calibrate_chessboards(paths: Sequence[Path], pattern: tuple[int, int], square_m: float = 1.0,
                          progress: Callable[[Path, bool], None] | None = None,
                          skipped: Callable[[Path, str], None] | None = None) -> CameraCalibration:
    """Zhang (2000) calibration from photos of a chessboard with ``pattern`` inner corners (cols, rows).

    square_m scales the board (it changes no intrinsic). Only photos of the most common size are used: a photo of
    another size (e.g. 1281x721 among 1280x720) is a resized or cropped copy whose pixels do not share the
    intrinsics, and keeping such photos raises the RMS error.
    ``skipped(path, why)`` hears of each photo that cannot be read (it is left out).
    Raises ValueError when no photo is readable or the board is found in none.
    """
    cols, rows = pattern
    found: list[tuple[tuple[int, int], np.ndarray]] = []
    readable = 0
    for p in paths:
        img = read_gray(p, skipped)
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
