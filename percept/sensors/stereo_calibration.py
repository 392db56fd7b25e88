"""A stereo rig from chessboard photo pairs: each camera's intrinsics, the right camera's pose, rectification.

Each camera is calibrated on its own (Zhang 2000, ``percept.sensors.chessboard``); then ``cv2.stereoCalibrate``
refines the rotation R and translation T taking points from the left camera's frame to the right's,
x_r = R x_l + T, by minimising the reprojection error of the board corners in both images of every pair with
the intrinsics fixed. ``cv2.stereoRectify`` (Bouguet's algorithm) rotates both cameras so that epipolar lines
are image rows: after rectification a point's rows agree in the two images and its depth is Z = f B / d.
Hartley & Zisserman, *Multiple View Geometry*, 2nd ed., sec. 9.2 (the fundamental matrix) and 11.12
(rectification).

The file (JSON) holds ``left`` and ``right`` (as a ``CameraCalibration``), R (3x3, row-major), T (3) [board
units, metres with ``square_m``], baseline_m = |T|, rms_px (stereo reprojection error), epipolar_px (mean
distance of a corner to the epipolar line of its partner, both ways) and the rectified projections P1, P2 (3x4).
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import cv2
import numpy as np

from percept.outputs import write_json_atomic

from .chessboard import (MIN_VIEWS, CameraCalibration, board_points, calibrate_points, chessboard_images,
                         find_corners, read_gray)


def stereo_photos(folder: Path) -> tuple[list[tuple[Path, Path]], list[Path]]:
    """(pairs, unpaired) of the photos in ``folder``: (left, right) pairs are files named left<X> and right<X>
    with the same <X> (e.g. left01.jpg, right01.jpg); unpaired are the other photos, sorted by name.
    ValueError when there is no pair."""
    files = {p.name.lower(): p for p in chessboard_images(folder)}
    pairs = [(p, files["right" + name[4:]]) for name, p in sorted(files.items())
             if name.startswith("left") and "right" + name[4:] in files]
    if not pairs:
        raise ValueError(f"{folder} holds no stereo pairs: name them left<N>.<ext> and right<N>.<ext>")
    paired = {p for pair in pairs for p in pair}
    return pairs, [p for _, p in sorted(files.items()) if p not in paired]


def stereo_pairs(folder: Path) -> list[tuple[Path, Path]]:
    """The (left, right) photo pairs of ``stereo_photos``; ValueError when there are none."""
    return stereo_photos(folder)[0]


@dataclass(frozen=True)
class StereoCalibration:
    """Two calibrated cameras and the pose of the right one in the left one's frame (see the module docstring).
    R: (3, 3); T: (3,) [m with square_m, else board squares]; P1, P2: (3, 4) rectified projections [px]."""

    left: CameraCalibration
    right: CameraCalibration
    R: np.ndarray
    T: np.ndarray
    rms_px: float
    epipolar_px: float
    P1: np.ndarray
    P2: np.ndarray
    pairs_used: int
    pairs_total: int

    @property
    def baseline_m(self) -> float:
        return float(np.linalg.norm(self.T))

    def to_dict(self) -> dict:
        return {"left": self.left.to_dict(), "right": self.right.to_dict(), "R": self.R.tolist(),
                "T": self.T.tolist(), "baseline_m": self.baseline_m, "rms_px": self.rms_px,
                "epipolar_px": self.epipolar_px, "P1": self.P1.tolist(), "P2": self.P2.tolist(),
                "pairs_used": self.pairs_used, "pairs_total": self.pairs_total}

    def save(self, path: Path) -> None:
        write_json_atomic(path, self.to_dict())


def _epipolar_error(pl: np.ndarray, pr: np.ndarray, left: CameraCalibration, right: CameraCalibration,
                    F: np.ndarray) -> float:
    """Mean distance [px] of undistorted corners to the epipolar lines of their partners: l_r = F x_l,
    l_l = F^T x_r (the check of OpenCV's stereo_calib sample)."""
    ul = cv2.undistortPoints(pl, left.K, np.asarray(left.dist), P=left.K).reshape(-1, 2)
    ur = cv2.undistortPoints(pr, right.K, np.asarray(right.dist), P=right.K).reshape(-1, 2)
    hl, hr = np.column_stack([ul, np.ones(len(ul))]), np.column_stack([ur, np.ones(len(ur))])
    lr, ll = hl @ F.T, hr @ F
    # distance of x to the line l: |l . x| / sqrt(l1^2 + l2^2)
    dr = np.abs(np.sum(lr * hr, axis=1)) / np.hypot(lr[:, 0], lr[:, 1])
    dl = np.abs(np.sum(ll * hl, axis=1)) / np.hypot(ll[:, 0], ll[:, 1])
    return float(np.mean(np.concatenate([dl, dr])))


def calibrate_stereo(pairs: list[tuple[Path, Path]], pattern: tuple[int, int], square_m: float = 1.0,
                     progress: Callable[[Path, bool], None] | None = None,
                     skipped: Callable[[Path, str], None] | None = None) -> StereoCalibration:
    """Calibrate a stereo rig from (left, right) chessboard photos; only pairs with the board found in both
    images, of the most common size (as for one camera), are used; ``skipped(path, why)`` hears of each pair left
    out for an unreadable photo or two sizes. ValueError when fewer than MIN_VIEWS remain."""
    obj = board_points(pattern, square_m)
    found: list[tuple[tuple[int, int], np.ndarray, np.ndarray]] = []
    for lp, rp in pairs:
        imgs = [read_gray(p, skipped) for p in (lp, rp)]
        readable = all(im is not None for im in imgs)
        ok = readable and imgs[0].shape == imgs[1].shape
        if readable and not ok and skipped is not None:
            skipped(lp, f"{lp} is {imgs[0].shape[1]}x{imgs[0].shape[0]} px but {rp.name} is "
                        f"{imgs[1].shape[1]}x{imgs[1].shape[0]} px")
        corners = [find_corners(im, pattern) for im in imgs] if ok else [None, None]
        ok = ok and all(c is not None for c in corners)
        if ok:
            found.append((imgs[0].shape[::-1], corners[0], corners[1]))
        if progress is not None:
            progress(lp, ok)
    size, n = Counter(s for s, _, _ in found).most_common(1)[0] if found else (None, 0)
    if n < MIN_VIEWS:
        raise ValueError(f"the {pattern[0]}x{pattern[1]} board was found in both images of only {n} of "
                         f"{len(pairs)} pairs; at least {MIN_VIEWS} are needed (check --pattern)")
    left_pts = [lc for s, lc, _ in found if s == size]
    right_pts = [rc for s, _, rc in found if s == size]
    total = len(pairs)
    left = calibrate_points(left_pts, size, pattern, square_m, n, total)
    right = calibrate_points(right_pts, size, pattern, square_m, n, total)
    # minimise the reprojection error of every corner in both images over R, T (and the board poses),
    # intrinsics fixed: x_r = R x_l + T
    rms, _, _, _, _, R, T, _, F = cv2.stereoCalibrate(
        [obj] * n, left_pts, right_pts, left.K, np.asarray(left.dist), right.K, np.asarray(right.dist), size,
        flags=cv2.CALIB_FIX_INTRINSIC,
        criteria=(cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 100, 1e-6))
    _, _, P1, P2, _, _, _ = cv2.stereoRectify(left.K, np.asarray(left.dist), right.K, np.asarray(right.dist), size,
                                              R, T, alpha=0)
    epi = _epipolar_error(np.concatenate(left_pts), np.concatenate(right_pts), left, right, F)
    return StereoCalibration(left, right, np.asarray(R), np.ravel(T), float(rms), epi, np.asarray(P1),
                             np.asarray(P2), n, total)
