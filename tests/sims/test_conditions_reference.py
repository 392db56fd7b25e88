"""The conditions' in-place and OpenCV arithmetic gives, bit for bit, what numpy's plain broadcast formulas give.

The reference below writes each step as one numpy expression; the fast one keeps scratch buffers between frames
and uses OpenCV's per-channel arithmetic in the same operations, so the frames are the same bytes on any CPU, and
buffers reused from frame to frame must carry nothing over.
"""

import cv2
import numpy as np
import pytest

from percept.sims import Condition, SimWorld, WorldConfig
from percept.sims.conditions import ConditionEffects, frame_rng
from percept.sims.world import scene_from_road


def reference(fx: ConditionEffects, img, seed, frame, camera, inv_depth=None, emission=None):
    c, H, W = fx.condition, fx.H, fx.W
    rng = frame_rng(seed, frame, camera)
    f = img.astype(np.float32)
    if c is Condition.NIGHT:
        if emission is None:
            emission = ((img[..., 2] > 180) & (img[..., 1] < 90)).astype(np.float32)
        inv = fx.ground_inv if inv_depth is None else inv_depth
        with np.errstate(divide="ignore"):
            z = np.where(inv > 0, 1.0 / np.maximum(inv, 1e-6), np.inf).astype(np.float32)
        z = np.minimum(z, 1e4)
        lateral = np.abs(fx.cam_y[camera] - fx.slope * z)
        spread = np.maximum(lateral - 1.5, 0) / (0.3 * z + 1.0)
        beam = np.exp(-spread * spread) / (1.0 + (z / 35.0) ** 2)
        beam[z >= 1e4] = 0.0
        gain = (0.08 + 1.1 * beam)[..., None]
        e = emission[..., None]
        lamps = f * e
        out = f * gain * (1.0 - e) + lamps
        rows, cols = np.flatnonzero(emission.any(axis=1)), np.flatnonzero(emission.any(axis=0))
        if len(rows):
            y0, y1 = max(rows[0] - 13, 0), min(rows[-1] + 14, H)
            x0, x1 = max(cols[0] - 13, 0), min(cols[-1] + 14, W)
            out[y0:y1, x0:x1] += cv2.GaussianBlur(lamps[y0:y1, x0:x1], (0, 0), 3) * 1.5
        out += 3.0 * rng.standard_normal(out.shape[:2], dtype=np.float32)[..., None]
    elif c is Condition.RAIN:
        out = 0.62 * cv2.GaussianBlur(img, (0, 0), 1.1).astype(np.float32) + 0.38 * np.array([150, 150, 145],
                                                                                              np.float32)
        streaks = np.zeros((H, W), np.float32)
        x, y = rng.uniform(0, W, 260), rng.uniform(0, H, 260)
        ln, val = rng.uniform(8, 25, 260), rng.uniform(20, 45, 260)
        for k in range(260):
            cv2.line(streaks, (int(x[k]), int(y[k])), (int(x[k] + 0.15 * ln[k]), int(y[k] + ln[k])),
                     float(val[k]), 1, cv2.LINE_AA)
        out += streaks[..., None]
        drops = np.zeros((H, W), np.float32)
        du, dv, dr = rng.uniform(0, W, 18), rng.uniform(0, H, 18), rng.uniform(4, 12, 18)
        for k in range(18):
            cv2.circle(drops, (int(du[k]), int(dv[k])), int(dr[k]), 1.0, -1, cv2.LINE_AA)
        drops = cv2.GaussianBlur(drops, (0, 0), 2)[..., None]
        small = cv2.GaussianBlur(cv2.pyrDown(cv2.pyrDown(out)), (0, 0), 1.5)
        blurred = cv2.resize(small, (W, H), interpolation=cv2.INTER_LINEAR)
        out = out * (1 - 0.6 * drops) + 0.6 * drops * blurred
    elif c is Condition.GLARE:
        su, sv = fx.sun_uv
        v, u = np.mgrid[0:H, 0:W].astype(np.float32)
        r = np.hypot(u - su, v - sv)
        glare = (255 * (np.exp(-r / 40.0) + 0.35 * np.exp(-r / 220.0))).astype(np.float32)[..., None]
        out = 0.8 * f + 0.2 * 235 + glare * 1.2
        for k, rad in ((0.6, 18), (1.3, 30), (1.8, 12)):
            gu, gv = W / 2 + (W / 2 - su) * k, H / 2 + (H / 2 - sv) * k
            ghost = np.zeros((H, W), np.float32)
            cv2.circle(ghost, (int(gu), int(gv)), rad, 45.0, -1, cv2.LINE_AA)
            out += cv2.GaussianBlur(ghost, (0, 0), 4)[..., None]
    else:
        out = f + 10.0 * rng.standard_normal(f.shape, dtype=np.float32)
        out += 3.0 * rng.standard_normal((H, 1, 1), dtype=np.float32)
    return np.clip(out, 0, 255).astype(np.uint8)


@pytest.fixture(scope="module")
def rendered():
    """Rendered frames with their maps: `crossing` (people) and `highway` (vehicles ahead, their tail lights)."""
    out = []
    for scenario in ("crossing", "highway"):
        w = SimWorld(WorldConfig(scenario, 1, autopilot=True))
        for _ in range(15):
            w.step()
        out.append(w.renderer.render(scene_from_road(w.env.road, w.ego, w.ids)))
    assert out[1].emission[0].any(), "the highway frame should show tail lights"
    return w.cfg.rig, out


@pytest.mark.parametrize("condition", [Condition.NIGHT, Condition.RAIN, Condition.GLARE, Condition.NOISE])
def test_the_fast_conditions_equal_the_plain_numpy_formulas_bit_for_bit(rendered, condition):
    rig, images = rendered
    fx = ConditionEffects(rig, condition)
    for frame, img in enumerate(images):
        for cam, side in enumerate((img.left, img.right)):
            got = fx.apply(side, 7, frame, cam, img.inv_depth[cam], img.emission[cam])
            assert np.array_equal(got, reference(fx, side, 7, frame, cam, img.inv_depth[cam], img.emission[cam]))
    # footage mode: no depth or lamp maps
    assert np.array_equal(fx.apply(images[0].left, 3, 5, 0), reference(fx, images[0].left, 3, 5, 0))
