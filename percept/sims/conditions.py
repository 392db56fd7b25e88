"""Photometric conditions applied to rendered frames: night, rain, glare, sensor noise, dropped frames.

Every effect draws from a generator seeded by (run seed, frame index, camera), so a run is reproducible.
"""

from __future__ import annotations

from enum import Enum

import cv2
import numpy as np

from percept.sensors import StereoRig


class Condition(str, Enum):
    CLEAR = "clear"
    NIGHT = "night"
    RAIN = "rain"
    GLARE = "glare"
    NOISE = "noise"
    DROPOUT = "dropout"


CONDITION_SUMMARY = {
    Condition.CLEAR: "daylight, dry, clean sensor",
    Condition.NIGHT: "dark sky, headlight beam on the road, glowing tail lights",
    Condition.RAIN: "low contrast, spray haze, blur, rain streaks and drops on the windscreen",
    Condition.GLARE: "low sun ahead: bloom, veiling glare and lens flare",
    Condition.NOISE: "strong sensor noise (sigma 10 grey levels) and row banding",
    Condition.DROPOUT: "10% of frames missing (the camera delivers nothing)",
}

DROPOUT_RATE = 0.10


def frame_rng(seed: int, frame: int, camera: int) -> np.random.Generator:
    return np.random.default_rng([seed, frame, camera, 0xC0FFEE])


def is_dropped(condition: Condition, seed: int, frame: int) -> bool:
    """Whether the camera delivers no frame at this step (dropout condition only)."""
    return condition is Condition.DROPOUT and frame_rng(seed, frame, 9).random() < DROPOUT_RATE


class ConditionEffects:
    """Precomputed masks of one rig for applying a condition to each camera's image."""

    def __init__(self, rig: StereoRig, condition: Condition):
        self.condition = Condition(condition)
        cam = rig.camera
        H, W = cam.height, cam.width
        hz = rig.horizon_row
        v, u = np.mgrid[0:H, 0:W].astype(np.float32)
        # per camera: column slope (u - cx) / fx and the camera's lateral offset (left +b/2, right -b/2) [m]
        self.slope = ((np.arange(W, dtype=np.float32) - cam.cx) / cam.fx)[None, :]
        self.cam_y = (rig.baseline_m / 2, -rig.baseline_m / 2)
        # the road's inverse depth per pixel, for images given without a depth map: 1/Z = (v - hz) / (f h)
        self.ground_inv = np.maximum(v - hz, 0.0) / np.float32(rig.mount_height_m * cam.fy)
        # glare: the sun low ahead, a little left of centre, above the horizon
        self.sun_uv = (cam.cx - 0.25 * cam.cx, max(hz - 0.18 * H, 10))
        r = np.hypot(u - self.sun_uv[0], v - self.sun_uv[1])
        self.glare = (255 * (np.exp(-r / 40.0) + 0.35 * np.exp(-r / 220.0))).astype(np.float32)[..., None]
        self.H, self.W = H, W

    def night_gain(self, inv_depth: np.ndarray | None, camera: int) -> np.ndarray:
        """(H, W, 1) light reaching each pixel's surface at night: ambient plus the headlight beam, which lights
        points ahead within about 1.5 m of the ego's centreline, widening and fading with distance. Computed from
        the camera's own inverse depth map (the road plane's without one), so that the beam lies on the world and
        both cameras see it at the surface's disparity."""
        inv = self.ground_inv if inv_depth is None else inv_depth
        with np.errstate(divide="ignore"):
            z = np.where(inv > 0, 1.0 / np.maximum(inv, 1e-6), np.inf).astype(np.float32)
        z = np.minimum(z, 1e4)
        # lateral distance from the centreline: y = y_cam - (u - cx) Z / fx
        lateral = np.abs(self.cam_y[camera] - self.slope * z)
        spread = np.maximum(lateral - 1.5, 0) / (0.3 * z + 1.0)
        beam = np.exp(-spread * spread) / (1.0 + (z / 35.0) ** 2)
        beam[z >= 1e4] = 0.0
        return (0.08 + 1.1 * beam)[..., None]

    def _night(self, f: np.ndarray, gain: np.ndarray, emission: np.ndarray) -> np.ndarray:
        """Lamps keep their light and glow; everything else is lit by ``gain``. Linear in each pixel's lamp
        fraction, so that a lamp's anti-aliased edge moves smoothly (a threshold would snap it to whole pixels)."""
        e = emission[..., None]
        lamps = f * e
        out = f * gain * (1.0 - e) + lamps
        rows, cols = np.flatnonzero(emission.any(axis=1)), np.flatnonzero(emission.any(axis=0))
        if len(rows):
            # the glow is local: blur only the lamps' bounding box, padded by the kernel radius (4 sigma)
            y0, y1 = max(rows[0] - 13, 0), min(rows[-1] + 14, self.H)
            x0, x1 = max(cols[0] - 13, 0), min(cols[-1] + 14, self.W)
            out[y0:y1, x0:x1] += cv2.GaussianBlur(lamps[y0:y1, x0:x1], (0, 0), 3) * 1.5
        return out

    def apply(self, img: np.ndarray, seed: int, frame: int, camera: int, inv_depth: np.ndarray | None = None,
              emission: np.ndarray | None = None) -> np.ndarray:
        """The condition applied to one camera's image (camera 0 left, 1 right). At night, ``inv_depth`` (that
        camera's (H, W) 1/Z map [1/m], 0 for sky) places the headlight beam on the world, and ``emission`` (the
        fraction of each pixel that is a lamp) says what glows; without them the beam lies on the road plane and
        red-and-bright pixels glow."""
        c = self.condition
        if c in (Condition.CLEAR, Condition.DROPOUT):
            return img
        rng = frame_rng(seed, frame, camera)
        f = img.astype(np.float32)
        if c is Condition.NIGHT:
            if emission is None:
                emission = ((img[..., 2] > 180) & (img[..., 1] < 90)).astype(np.float32)
            out = self._night(f, self.night_gain(inv_depth, camera), emission)
            out += 3.0 * rng.standard_normal(out.shape[:2], dtype=np.float32)[..., None]
        elif c is Condition.RAIN:
            haze = np.array([150, 150, 145], np.float32)
            out = 0.62 * cv2.GaussianBlur(img, (0, 0), 1.1).astype(np.float32) + 0.38 * haze
            streaks = np.zeros((self.H, self.W), np.float32)
            x, y = rng.uniform(0, self.W, 260), rng.uniform(0, self.H, 260)
            ln, val = rng.uniform(8, 25, 260), rng.uniform(20, 45, 260)
            for k in range(260):
                cv2.line(streaks, (int(x[k]), int(y[k])), (int(x[k] + 0.15 * ln[k]), int(y[k] + ln[k])),
                         float(val[k]), 1, cv2.LINE_AA)
            out += streaks[..., None]
            drops = np.zeros((self.H, self.W), np.float32)
            du, dv, dr = rng.uniform(0, self.W, 18), rng.uniform(0, self.H, 18), rng.uniform(4, 12, 18)
            for k in range(18):
                cv2.circle(drops, (int(du[k]), int(dv[k])), int(dr[k]), 1.0, -1, cv2.LINE_AA)
            drops = cv2.GaussianBlur(drops, (0, 0), 2)[..., None]
            # what a drop shows is the scene blurred (sigma 6 px): blurred at quarter size, scaled back up
            small = cv2.GaussianBlur(cv2.pyrDown(cv2.pyrDown(out)), (0, 0), 1.5)
            blurred = cv2.resize(small, (self.W, self.H), interpolation=cv2.INTER_LINEAR)
            out = out * (1 - 0.6 * drops) + 0.6 * drops * blurred
        elif c is Condition.GLARE:
            out = 0.8 * f + 0.2 * 235 + self.glare * 1.2
            # lens flare: ghosts on the line through the sun and the image centre
            su, sv = self.sun_uv
            for k, rad in ((0.6, 18), (1.3, 30), (1.8, 12)):
                gu, gv = self.W / 2 + (self.W / 2 - su) * k, self.H / 2 + (self.H / 2 - sv) * k
                ghost = np.zeros((self.H, self.W), np.float32)
                cv2.circle(ghost, (int(gu), int(gv)), rad, 45.0, -1, cv2.LINE_AA)
                out += cv2.GaussianBlur(ghost, (0, 0), 4)[..., None]
        else:  # NOISE
            out = f + 10.0 * rng.standard_normal(f.shape, dtype=np.float32)
            out += 3.0 * rng.standard_normal((self.H, 1, 1), dtype=np.float32)
        return np.clip(out, 0, 255).astype(np.uint8)
