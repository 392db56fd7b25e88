"""The road as a plane between two monocular frames: its homography for a camera motion, the plane recovered
from a measured homography, and the image region where a level road lies ahead (Hartley & Zisserman, sec. 13.1).
"""

from __future__ import annotations

import numpy as np


def plane_homography(K: np.ndarray, R: np.ndarray, t: np.ndarray, m: np.ndarray) -> np.ndarray:
    """(3, 3) homography from previous to current pixels of the plane m^T X = 1 (X in the previous camera's
    frame), for the motion x_cur = R x_prev + t (H&Z eq. 13.2)."""
    # X_cur = R X + t (m^T X) = (R + t m^T) X  ->  H = K (R + t m^T) K^-1
    return K @ (R + np.outer(t.reshape(3), m)) @ np.linalg.inv(K)


def plane_from_homography(K: np.ndarray, R: np.ndarray, t: np.ndarray, H: np.ndarray) -> np.ndarray | None:
    """The plane m (3,) (m^T X = 1 in the previous camera's frame) whose homography for (R, t) is nearest to H
    (up to scale, linear least squares); None when H does not fit a plane."""
    A = np.linalg.inv(K) @ H @ K
    # A = lam R + t w^T with w = lam m: 9 equations in (lam, w)
    M = np.column_stack([R.ravel(), np.kron(t.reshape(3, 1), np.eye(3))])
    x = np.linalg.lstsq(M, A.ravel(), rcond=None)[0]
    return x[1:] / x[0] if abs(x[0]) > 1e-9 and np.all(np.isfinite(x)) else None


class RoadRegion:
    """The road region of one image size: trapezoid mask, its crop box, and warps in crop coordinates."""

    def __init__(self, K: np.ndarray, height_m: float, shape: tuple[int, int], cfg):
        (fx, fy), (cx, cy) = np.diag(K)[:2], K[:2, 2]
        v, u = np.mgrid[0:shape[0], 0:shape[1]].astype(np.float64)
        below = v - cy
        # level road: Z = fy H / (v - cy), X = (u - cx) Z / fx; keep Z < range and |X| < half width
        road = (below > fy * height_m / cfg.road_range_m) & (
            np.abs(u - cx) * fy * height_m < cfg.road_half_width_m * fx * below)
        self.mask = np.where(road, 255, 0).astype(np.uint8)
        rows, cols = np.flatnonzero(road.any(1)), np.flatnonzero(road.any(0))
        self.ok = len(rows) > 8 and len(cols) > 8
        if self.ok:
            self.box = (rows[0], rows[-1] + 1, cols[0], cols[-1] + 1)
            self.crop_mask = self.mask[rows[0]:rows[-1] + 1, cols[0]:cols[-1] + 1]
            # crop-to-image translation of the template (previous image)
            self.T_tpl = np.array([[1.0, 0, cols[0]], [0, 1, rows[0]], [0, 0, 1]])

    def to_crop(self, H: np.ndarray) -> np.ndarray:
        """Image homography (previous -> current pixels) as one from template crop to current pixels."""
        C = H @ self.T_tpl
        return C / C[2, 2]

    def template(self, prev: np.ndarray) -> np.ndarray:
        v0, v1, u0, u1 = self.box
        return prev[v0:v1, u0:u1]
