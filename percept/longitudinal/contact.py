"""Range from where the obstacle meets the road: the bottom edge of its tyres, seen on the ground plane.

A road point on image row v is at the distance the rig's ground homography gives it; the tyres' lowest row is
where the obstacle touches the road, so its range is that distance less the rear overhang (Stein, Mano &
Shashua, "Vision-based ACC with a single camera", IV 2003: Z = f H / (y - y_horizon)). The edge is the
strongest dark-to-bright step going down the outer columns of the obstacle's box (tyres over asphalt), searched
only near the row the stereo range predicts. Its noise grows as Z^2: dZ/dv = Z^2 / (f H).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from percept.compiled import kernel
from percept.sensors import StereoRig


@dataclass(frozen=True)
class ContactConfig:
    """Settings of the ground-contact range: the tyres' place, the search window and the edge's strength and noise."""

    # from the rear face to where the rear tyres touch the road [m] (a car's is 0.5-1.0 m; the simulator's cars 0.57 m)
    rear_overhang_m: float = 0.57
    wheel_frac: float = 0.15  # fraction of the box width on each side searched for tyres
    window: tuple[float, float] = (0.8, 1.25)  # ranges searched, as factors of the guess (nearer, farther)
    min_step: float = 12.0  # smallest dark-to-bright step [grey levels]
    sigma_row_px: float = 0.29  # the edge row's noise [px] (an unsmoothed edge: uniform over a pixel, 1/sqrt(12))


@dataclass(frozen=True)
class Contact:
    """range_m: camera to the obstacle's rear face along the road [m]; sigma_m: its standard error [m];
    row_px: the image row of the contact edge [px]; step: the edge's strength (grey levels)."""

    range_m: float
    sigma_m: float
    row_px: float
    step: float


class ContactRange:
    """Ground-contact range of an obstacle box, near a range guess."""

    def __init__(self, rig: StereoRig, cfg: ContactConfig = ContactConfig()):
        self.rig, self.cfg = rig, cfg
        self.cam_x = float(rig.camera_position()[0])
        # the compiled edge search (compiled once after an install) loaded now, on a frame's argument types (a
        # simulated frame's images are read-only, others need not be)
        strip = np.zeros((3, 4), np.uint8)
        _tyre_edge(strip, 0, 1, 3, 4)
        strip.flags.writeable = False
        _tyre_edge(strip, 0, 1, 3, 4)

    def _rows(self, *ranges_m: float) -> list[float]:
        """Image rows of the road at ``ranges_m`` ahead of the camera (rows depend on distance only: no roll), in one
        projection."""
        uv, _ = self.rig.project_vehicle_points(np.array([[self.cam_x + r, 0.0, 0.0] for r in ranges_m]))
        return uv[:, 1].tolist()

    def measure(self, gray: np.ndarray, box: tuple[int, int, int, int], range_guess_m: float) -> Contact | None:
        """The contact range of the obstacle in ``box`` (u0, v0, u1, v1) of the grey left image, searched between
        ``window`` times the guess [m]; None without a clear edge there."""
        cfg, cam = self.cfg, self.rig.camera
        u0, _, u1, _ = box
        z = range_guess_m + cfg.rear_overhang_m
        v_far, v_near = self._rows(z * cfg.window[1], z * cfg.window[0])
        top, bottom = int(math.floor(v_far)), int(math.ceil(v_near)) + 1
        top, bottom = max(top, 0), min(bottom, gray.shape[0] - 1)
        k = max(int(round((u1 - u0) * cfg.wheel_frac)), 1)
        if bottom - top < 2 or u1 - u0 < 4:
            return None
        (a0, a1, _), (b0, b1, _) = slice(u0, u0 + k).indices(gray.shape[1]), slice(u1 - k, u1).indices(gray.shape[1])
        i, step = _tyre_edge(gray[top:bottom + 1], a0, a1, b0, b1)
        step = np.float32(step)  # (a float32's value; compared as numpy compares one)
        if step < cfg.min_step:
            return None
        # the edge lies between the last tyre row and the first road row
        row = top + i + 0.5
        x = self.rig.image_to_ground(np.array([[(u0 + u1) / 2, row]]))[0, 0] - self.cam_x
        if not np.isfinite(x) or x <= cfg.rear_overhang_m:
            return None
        h = self.rig.mount_height_m
        # dZ/dv = Z^2 / (f H)
        sigma = x * x / (cam.fy * h) * cfg.sigma_row_px
        return Contact(float(x - cfg.rear_overhang_m), float(sigma), float(row), float(step))


@kernel()
def _tyre_edge(strip, a0, a1, b0, b1):  # pragma: no cover - compiled
    """The strongest dark-to-bright step down the rows of ``strip`` (rows, w) uint8 in the mean grey level of its
    columns a0..a1 and b0..b1 (the box's outer columns): (i, step), the step from row i to i + 1, the first largest.
    In numpy's arithmetic (the columns as float32, np.mean along the rows, np.diff, np.argmax): the sums of whole grey
    levels are exact in any order (below 2^24: up to 65 793 columns), the mean their float32 quotient by the count."""
    rows = strip.shape[0]
    count = np.float32((a1 - a0) + (b1 - b0))
    profile = np.empty(rows, np.float32)
    for r in range(rows):
        total = 0.0
        for c in range(a0, a1):
            total += strip[r, c]
        for c in range(b0, b1):
            total += strip[r, c]
        profile[r] = np.float32(total) / count
    # step between row v and v + 1: brighter below where the tyres end and the road begins
    best, i = profile[1] - profile[0], 0
    for r in range(1, rows - 1):
        step = profile[r + 1] - profile[r]
        if step > best:
            best, i = step, r
    return i, best
