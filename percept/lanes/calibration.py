"""Camera geometry of recorded footage: intrinsics from chessboard photos, pitch from the lane lines.

Zhang's method (Z. Zhang, "A flexible new technique for camera calibration", PAMI 22(11), 2000) as OpenCV
implements it: the inner corners of a planar chessboard are found (``cv2.findChessboardCorners``), refined to
sub-pixel accuracy (``cv2.cornerSubPix``, the saddle point where the gradients are orthogonal to the lines to
the corner), and ``cv2.calibrateCamera`` estimates K and the Brown-Conrady distortion (k1, k2, p1, p2, k3) by
minimising the reprojection error over all views (Levenberg-Marquardt). See also Hartley & Zisserman,
*Multiple View Geometry*, 2nd ed., sec. 7.4 and 8.8.

Extrinsics come from the road itself: the near parts of the lane lines are straight and parallel on the ground,
so their images meet at the road's vanishing point, whose row is the horizon (Hartley & Zisserman sec. 8.6);
with the camera rolled by ~0 and yawed by a little, pitch = atan((cy - v_vp) / fy). Segments come from a
probabilistic Hough transform on Canny edges; the point is the pair hypothesis that the most segment length
points at (an exhaustive, deterministic RANSAC), refined by weighted least squares; ``marking_vanishing_point``
refines it from the lane-marking evidence the detector labelled left and right.

The calibration file (JSON) holds fx, fy, cx, cy [px], width, height [px], dist (OpenCV order), rms_px
(RMS reprojection error [px]) and the counts of photos used; ``percept lanes --calib FILE`` reads it.
"""

from __future__ import annotations

import json
import math
import re
from collections import Counter
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Callable, Sequence

import cv2
import numpy as np

from percept.sensors import PinholeCamera, StereoRig

from .evidence import marking_brightness
from .types import LaneFit, MarkingEvidence

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".ppm", ".pgm")


def parse_pattern(text: str) -> tuple[int, int]:
    """'9x6' -> (9, 6): inner corners per row and per column of the chessboard (each at least 2)."""
    m = re.fullmatch(r"\s*(\d+)\s*[xX×]\s*(\d+)\s*", str(text))
    if m is None:
        raise ValueError(f"pattern {text!r} is not COLSxROWS of inner corners, e.g. 9x6")
    cols, rows = int(m.group(1)), int(m.group(2))
    if cols < 2 or rows < 2:
        raise ValueError(f"pattern {text!r} needs at least 2x2 inner corners")
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


def calibrate_chessboards(paths: Sequence[Path], pattern: tuple[int, int], square_m: float = 1.0,
                          progress: Callable[[Path, bool], None] | None = None) -> CameraCalibration:
    """Zhang (2000) calibration from photos of a chessboard with ``pattern`` inner corners (cols, rows).

    square_m scales the board (it changes no intrinsic). Only photos of the most common size are used: a photo of
    another size (e.g. 1281x721 among 1280x720) is a resized or cropped copy whose pixels do not share the
    intrinsics, and keeping such photos raises the RMS error (udacity camera_cal: 1.00 px with, 0.85 px without).
    Raises ValueError when no photo is readable or the board is found in none.
    """
    cols, rows = pattern
    # board points (X, Y, 0): the corner grid in board units
    obj = np.zeros((cols * rows, 3), np.float32)
    obj[:, :2] = np.mgrid[0:cols, 0:rows].T.reshape(-1, 2) * square_m
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
    size = Counter(s for s, _ in found).most_common(1)[0][0]
    pts = [c for s, c in found if s == size]
    # minimise sum_i sum_j || x_ij - pi(K, dist, R_i, t_i, X_j) ||^2 (Zhang 2000, eq. 10 with distortion)
    rms, K, dist, _, _ = cv2.calibrateCamera([obj] * len(pts), pts, size, None, None)
    return CameraCalibration(float(K[0, 0]), float(K[1, 1]), float(K[0, 2]), float(K[1, 2]), int(size[0]),
                             int(size[1]), tuple(float(k) for k in np.ravel(dist)), float(rms), len(pts),
                             len(found), readable, (cols, rows))


@dataclass(frozen=True)
class VanishingPoint:
    """Vanishing point of the lane lines (u, v) [px]; segments: how many line segments (or marking points)
    agree; support_px: their total length [px] (0 for marking points); source: "segments" | "markings"."""

    u: float
    v: float
    segments: int
    support_px: float
    source: str = "segments"


def _segments(image: np.ndarray, top: int, bottom: int) -> np.ndarray:
    """Line segments (N, 4) as (u1, v1, u2, v2) [px] between rows top and bottom: probabilistic Hough on the
    Canny edges of the grey image, plus on the edges of thin bright stripes (a horizontal top-hat of the marking
    brightness, 4 % of the width wide), which keeps faint yellow-on-concrete lines."""
    w = image.shape[1]
    roi = image[top:bottom]
    gray = cv2.cvtColor(roi, cv2.COLOR_BGR2GRAY)
    mark = np.clip(marking_brightness(roi), 0, 255).astype(np.uint8)
    kernel = cv2.getStructuringElement(cv2.MORPH_RECT, (int(0.04 * w) | 1, 1))
    stripes = ((cv2.morphologyEx(mark, cv2.MORPH_TOPHAT, kernel) > 20) * 255).astype(np.uint8)
    out = []
    for edges in (cv2.Canny(cv2.GaussianBlur(gray, (5, 5), 0), 50, 150), cv2.Canny(stripes, 50, 150)):
        segs = cv2.HoughLinesP(edges, 1, np.pi / 180, 30, minLineLength=0.03 * w, maxLineGap=0.01 * w)
        if segs is not None:
            # back to full-image rows
            out.append(segs.reshape(-1, 4).astype(np.float64) + np.array([0.0, top, 0.0, top]))
    return np.vstack(out) if out else np.zeros((0, 4))


def estimate_vanishing_point(image: np.ndarray, roi_top_frac: float = 0.5, bottom_margin_frac: float = 0.07,
                             max_angle_err_rad: float = math.radians(1.5)) -> VanishingPoint | None:
    """Vanishing point of the lane lines in a BGR image, or None when no left/right pair of segments agrees.

    Segments are searched between rows roi_top_frac * H and (1 - bottom_margin_frac) * H (the hood).
    Segments between 20 and 75 deg from horizontal are lane-line candidates; left lines lean one way
    (du/dv < 0), right lines the other. A segment supports a candidate point when the direction from its
    midpoint to the point is within ``max_angle_err_rad`` of its own and the point lies above it.
    """
    h, w = image.shape[:2]
    s = _segments(image, int(roi_top_frac * h), int((1 - bottom_margin_frac) * h))
    d = s[:, 2:] - s[:, :2]
    ang = np.arctan2(np.abs(d[:, 1]), np.abs(d[:, 0]))
    keep = (ang > math.radians(20)) & (ang < math.radians(75))
    s, d = s[keep], d[keep]
    length = np.hypot(d[:, 0], d[:, 1])
    lean = np.sign(d[:, 0] * d[:, 1])
    # homogeneous line through both end points: l = p1 x p2, scaled so that l . (u, v, 1) is a distance [px]
    ones = np.ones((len(s), 1))
    lines = np.cross(np.hstack([s[:, :2], ones]), np.hstack([s[:, 2:], ones]))
    lines /= np.hypot(lines[:, 0], lines[:, 1])[:, None] + 1e-12
    mid = (s[:, :2] + s[:, 2:]) / 2
    left = [i for i in np.argsort(-length) if lean[i] < 0][:30]
    right = [i for i in np.argsort(-length) if lean[i] > 0][:30]
    best = None
    for i in left:
        for j in right:
            # intersection of two lines: x = l_i x l_j (H&Z sec. 2.2.1)
            x = np.cross(lines[i], lines[j])
            if abs(x[2]) < 1e-9:
                continue
            x = x[:2] / x[2]
            if not (0 <= x[0] < w and 0 <= x[1] < h):
                continue
            to = x - mid
            dist = np.hypot(to[:, 0], to[:, 1]) + 1e-9
            # |cos| of the angle between a segment and the ray from its midpoint to x
            cos = np.abs(np.sum(to * d, axis=1)) / (dist * length)
            inl = (cos > math.cos(max_angle_err_rad)) & (to[:, 1] < 0)
            # both leans must be seen by at least two segments each (one stray mark does not make a lane line)
            if not (inl[i] and inl[j]) or (inl & (lean < 0)).sum() < 2 or (inl & (lean > 0)).sum() < 2:
                continue
            score = float(length[inl].sum())
            if best is None or score > best[0]:
                best = (score, inl)
    if best is None:
        return None
    score, inl = best
    # refine: min_x sum_k L_k^2 (l_k . (x, 1))^2 over the supporting segments, linear in x
    A = lines[inl, :2] * length[inl, None]
    b = -lines[inl, 2] * length[inl]
    (u, v), *_ = np.linalg.lstsq(A, b, rcond=None)
    return VanishingPoint(float(u), float(v), int(inl.sum()), score)


def marking_vanishing_point(evidence: MarkingEvidence, fit: LaneFit, span_m: float = 20.0,
                            min_points: int = 8) -> VanishingPoint | None:
    """Vanishing point from the marking evidence a fit labelled left and right: a straight image line
    u = p + q v per side through the points of the first ``span_m`` metres (weights sqrt(strength)), and their
    intersection. Over the same range both boundaries have the same heading, so on a curve too the two tangent
    lines meet on the horizon. None without ``min_points`` labelled points on each side."""
    x = evidence.points_m[:, 0]
    near = x < x.min() + span_m if len(x) else np.zeros(0, bool)
    lines, used = [], 0
    for side in (1, -1):
        m = near & (fit.side == side)
        if m.sum() < min_points:
            return None
        u, v = evidence.uv_px[m].T
        w = np.sqrt(np.clip(evidence.strength[m], 1e-6, None))
        # weighted least squares for u = p + q v
        (q, p), *_ = np.linalg.lstsq(np.column_stack([v, np.ones_like(v)]) * w[:, None], u * w, rcond=None)
        lines.append(np.array([1.0, -q, -p]))
        used += int(m.sum())
    x_h = np.cross(lines[0], lines[1])
    if abs(x_h[2]) < 1e-9:
        return None
    return VanishingPoint(float(x_h[0] / x_h[2]), float(x_h[1] / x_h[2]), used, 0.0, "markings")


def make_rig(camera: PinholeCamera, horizon_row_px: float, mount_height_m: float) -> StereoRig:
    """Monocular rig: the camera at the vehicle origin (mount_x_m = 0), pitched so that the ground's horizon
    falls on ``horizon_row_px``: pitch = atan((cy - v_h) / fy) [rad]."""
    pitch = math.atan((camera.cy - horizon_row_px) / camera.fy)
    pitch = float(np.clip(pitch, -0.45, 0.45))
    return StereoRig(camera=camera, baseline_m=0.54, mount_height_m=mount_height_m, pitch_rad=pitch, mount_x_m=0.0)
