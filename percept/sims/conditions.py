"""Photometric conditions applied to rendered frames: night, rain, glare, sensor noise, dropped frames.

Every effect draws from a generator seeded by (run seed, frame index, camera), so a run is reproducible.
"""

from __future__ import annotations

from enum import Enum

import cv2
import numpy as np

from percept.sensors import StereoRig

from . import condition_passes as passes
from .normals import standard_normal_f32


class Condition(str, Enum):
    """The photometric condition a run's cameras see (``CONDITION_SUMMARY`` says what each does)."""

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
    """The generator of one camera's effects in one frame of a run."""
    return np.random.default_rng([seed, frame, camera, 0xC0FFEE])


def is_dropped(condition: Condition, seed: int, frame: int) -> bool:
    """Whether the camera delivers no frame at this step (dropout condition only)."""
    return condition is Condition.DROPOUT and frame_rng(seed, frame, 9).random() < DROPOUT_RATE


AMBIENT_NIGHT = np.float32(0.08)
"""The light reaching every surface at night besides the ego's headlight beam (a share of the daylight)."""


class ConditionEffects:
    """Precomputed masks of one rig for applying a condition to each camera's image. The ego's headlight beam and the
    low sun (glare) lie ahead of the car: a rig that looks back (``StereoRig.looks_back``) sees at night only the
    ambient light and the lamps (the headlights of the cars behind face it), and under the glare condition no sun."""

    def __init__(self, rig: StereoRig, condition: Condition):
        self.condition = Condition(condition)
        self.looks_back = rig.looks_back
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
        glare = (255 * (np.exp(-r / 40.0) + 0.35 * np.exp(-r / 220.0))).astype(np.float32)
        self._glare_lit = np.repeat((glare * 1.2)[..., None], 3, axis=2)
        # lens flare: ghosts on the line through the sun and the image centre, each kept with the box where its
        # blur is not zero (the blur's kernel reaches 4 sigma + 1 px beyond the disc)
        self._ghosts = []
        su, sv = self.sun_uv
        for k, rad in ((0.6, 18), (1.3, 30), (1.8, 12)):
            gu, gv = W / 2 + (W / 2 - su) * k, H / 2 + (H / 2 - sv) * k
            ghost = np.zeros((H, W), np.float32)
            cv2.circle(ghost, (int(gu), int(gv)), rad, 45.0, -1, cv2.LINE_AA)
            ghost = cv2.GaussianBlur(ghost, (0, 0), 4)[..., None]
            rows, cols = np.flatnonzero(ghost.any(axis=(1, 2))), np.flatnonzero(ghost.any(axis=(0, 2)))
            if len(rows):
                box = np.s_[rows[0]:rows[-1] + 1, cols[0]:cols[-1] + 1]
                self._ghosts.append((box, ghost[box]))
        self._buffers: dict[str, np.ndarray] = {}
        # 0.38 haze, per channel (float32)
        self._haze_f32 = np.float32(0.38) * np.array([150, 150, 145], np.float32)
        self.H, self.W = H, W
        if self.condition not in (Condition.CLEAR, Condition.DROPOUT):
            # the condition's compiled passes loaded (or compiled, once after an install) and its scratch buffers made
            # now, by applying it once to a black frame of the rig's size, not in a timed frame
            self.apply(np.zeros((H, W, 3), np.uint8), 0, 0, 0)

    @property
    def reads_emission(self) -> bool:
        """Whether ``apply`` reads the renderer's lamp map (only the night does: what glows), so that a renderer can
        skip drawing one for the other conditions."""
        return self.condition is Condition.NIGHT

    def night_gain(self, inv_depth: np.ndarray | None, camera: int) -> np.ndarray:
        """(H, W) light reaching each pixel's surface at night: ambient plus the headlight beam, which lights
        points ahead within about 1.5 m of the ego's centreline, widening and fading with distance. Computed from
        the camera's own inverse depth map (the road plane's without one), so that the beam lies on the world and
        both cameras see it at the surface's disparity. A rig looking back gets the ambient light alone."""
        return self._night_gain(inv_depth, camera).copy()

    def _night_gain(self, inv_depth: np.ndarray | None, camera: int) -> np.ndarray:
        """``night_gain`` written in place on scratch buffers (the result is one of them, valid until the next
        call)."""
        if self.looks_back:
            # no beam behind the car: the ambient light alone (what the beam's gain is where the beam is 0)
            t = self._scratch("t")
            t.fill(AMBIENT_NIGHT)
            return t
        inv = self.ground_inv if inv_depth is None else inv_depth
        z, t = self._scratch("noise"), self._scratch("t")
        passes.beam_spread(inv, self.slope, np.float32(self.cam_y[camera]), z, t)
        # beam = exp(-spread^2) / (1 + (Z / 35)^2): numpy's exp, between the two compiled passes
        np.exp(t, out=t)
        passes.beam_gain(z, t)
        return t

    def night(self, img: np.ndarray, gain: np.ndarray, emission: np.ndarray) -> np.ndarray:
        """Lamps keep their light and glow; everything else is lit by ``gain``. Linear in each pixel's lamp
        fraction, so that a lamp's anti-aliased edge moves smoothly (a threshold would snap it to whole pixels).
        Where no lamp is (e = 0) the mix is f gain exactly (f: ``img`` in float32), so it is computed in full only
        in the lamps' box."""
        out = self._scratch("out", 3)
        passes.lit(img, gain, out)
        rows, cols = np.flatnonzero(emission.any(axis=1)), np.flatnonzero(emission.any(axis=0))
        if len(rows):
            # the glow is local: blur only the lamps' bounding box, padded by the kernel radius (4 sigma)
            y0, y1 = max(rows[0] - 13, 0), min(rows[-1] + 14, self.H)
            x0, x1 = max(cols[0] - 13, 0), min(cols[-1] + 14, self.W)
            box = np.s_[y0:y1, x0:x1]
            fb, e = img[box].astype(np.float32), emission[box][..., None]
            lamps = fb * e
            # out = f gain (1 - e) + f e
            out[box] = fb * gain[box][..., None] * (1.0 - e) + lamps
            out[box] += cv2.GaussianBlur(lamps, (0, 0), 3) * 1.5
        return out

    def _scratch(self, name: str, channels: int = 1) -> np.ndarray:
        """A float32 (H, W[, channels]) buffer kept between frames: a fresh full-frame array each time costs
        more in page faults than the arithmetic done in it."""
        b = self._buffers.get(name)
        if b is None:
            shape = (self.H, self.W) if channels == 1 else (self.H, self.W, channels)
            b = self._buffers[name] = np.empty(shape, np.float32)
        return b

    def _rain(self, img: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        streaks = self._scratch("streaks")
        streaks.fill(0)
        x, y = rng.uniform(0, self.W, 260), rng.uniform(0, self.H, 260)
        ln, val = rng.uniform(8, 25, 260), rng.uniform(20, 45, 260)
        for k in range(260):
            cv2.line(streaks, (int(x[k]), int(y[k])), (int(x[k] + 0.15 * ln[k]), int(y[k] + ln[k])),
                     float(val[k]), 1, cv2.LINE_AA)
        # out = 0.62 blur(img) + 0.38 haze + the streaks
        out = self._scratch("out", 3)
        passes.hazy(cv2.GaussianBlur(img, (0, 0), 1.1), np.float32(0.62), self._haze_f32, streaks, out)
        drops = self._scratch("drops")
        drops.fill(0)
        du, dv, dr = rng.uniform(0, self.W, 18), rng.uniform(0, self.H, 18), rng.uniform(4, 12, 18)
        for k in range(18):
            cv2.circle(drops, (int(du[k]), int(dv[k])), int(dr[k]), 1.0, -1, cv2.LINE_AA)
        d = cv2.GaussianBlur(drops, (0, 0), 2, dst=self._scratch("d"))
        # what a drop shows is the scene blurred (sigma 6 px): blurred at quarter size, scaled back up
        small = cv2.GaussianBlur(cv2.pyrDown(cv2.pyrDown(out)), (0, 0), 1.5)
        blurred = cv2.resize(small, (self.W, self.H), dst=self._scratch("blurred", 3), interpolation=cv2.INTER_LINEAR)
        # out = out (1 - 0.6 d) + 0.6 d blurred
        passes.through_drops(out, d, blurred)
        return out

    def _glare(self, img: np.ndarray) -> np.ndarray:
        # out = 0.8 f + 0.2 * 235 + 1.2 glare, then the lens flare's ghosts
        out = self._scratch("out", 3)
        passes.glared(img, np.float32(0.8), np.float32(0.2 * 235), self._glare_lit, out)
        for box, ghost in self._ghosts:
            out[box] += ghost
        return out

    def apply(self, img: np.ndarray, seed: int, frame: int, camera: int, inv_depth: np.ndarray | None = None,
              emission: np.ndarray | None = None) -> np.ndarray:
        """The condition applied to one camera's image (camera 0 left, 1 right; a second rig's cameras take other
        numbers, 2 and 3 for the rear rig, so that their random draws are their own). At night, ``inv_depth`` (that
        camera's (H, W) 1/Z map [1/m], 0 for sky) places the headlight beam on the world, and ``emission`` (the
        fraction of each pixel that is a lamp) says what glows; without them the beam lies on the road plane and
        red-and-bright pixels glow."""
        c = self.condition
        if c in (Condition.CLEAR, Condition.DROPOUT) or (c is Condition.GLARE and self.looks_back):
            return img
        rng = frame_rng(seed, frame, camera)
        if c is Condition.NIGHT:
            if emission is None:
                emission = ((img[..., 2] > 180) & (img[..., 1] < 90)).astype(np.float32)
            out = self.night(img, self._night_gain(inv_depth, camera), emission)
            n = standard_normal_f32(rng, self._scratch("noise"))
            # out + 3 n on every channel, clipped and truncated to uint8
            return passes.with_noise_uint8(out, n, np.float32(3.0))
        elif c is Condition.RAIN:
            out = self._rain(img, rng)
        elif c is Condition.GLARE:
            out = self._glare(img)
        else:  # NOISE
            n = standard_normal_f32(rng, self._scratch("out", 3))
            # out = f + 10 n, then a row banding of 3 n_row, clipped and truncated to uint8
            return passes.noisy_uint8(img, n, np.float32(3.0) * rng.standard_normal((self.H, 1), dtype=np.float32))
        # rain and glare: numpy's clip and cast (a compiled pass for them alone is no faster; the night's and the
        # noise's are fused with their last sum above)
        np.clip(out, 0, 255, out=out)
        return out.astype(np.uint8)
