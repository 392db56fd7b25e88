"""Vehicles as textured 3D boxes: body, cabin with glass, wheels, lights and a number plate."""

from __future__ import annotations

import numpy as np

from .patches import PatchBuilder
from .scene import ObjectState

BODY_COLORS = [(40, 40, 160), (170, 170, 170), (30, 30, 30), (230, 230, 230), (140, 80, 30),
               (60, 120, 60), (40, 90, 200), (110, 110, 120), (20, 20, 90), (200, 160, 90)]
GLASS = (45, 40, 35)
TYRE = (25, 25, 25)
TAIL = (40, 40, 230)
HEAD = (225, 235, 240)
PLATE = (235, 235, 235)
EPS = 0.01


def vehicle_patches(b: PatchBuilder, obj: ObjectState, body_texture: int) -> None:
    """Add the patches of one vehicle. Frame: the object's pose, x forward, y left, z up."""
    p = obj.pose
    c, s = np.cos(p.yaw_rad), np.sin(p.yaw_rad)
    ax = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])  # rows: forward, left, up (world)
    centre = np.array([p.x_m, p.y_m, 0.0])
    L, W, Hh = obj.length_m, obj.width_m, obj.height_m
    rng = np.random.default_rng(obj.style)
    color = BODY_COLORS[int(rng.integers(len(BODY_COLORS)))]

    def at(x, y, z):
        return centre + x * ax[0] + y * ax[1] + z * ax[2]

    z_body0, z_body1 = 0.32, 0.58 * Hh + 0.1
    b.box(at(0, 0, (z_body0 + z_body1) / 2), ax, (L, W, z_body1 - z_body0), color, texture=body_texture,
          obj_id=obj.obj_id, bottom=True)
    cab_len = 0.5 * L
    b.box(at(-0.08 * L, 0, (z_body1 + Hh) / 2), ax, (cab_len, W * 0.86, Hh - z_body1), GLASS, obj_id=obj.obj_id)
    # roof in body colour over the glasshouse
    b.add(at(-0.08 * L - cab_len / 2 + 0.15, -W * 0.4, Hh + EPS), (cab_len - 0.3) * ax[0], 0.8 * W * ax[1], color,
          texture=body_texture, obj_id=obj.obj_id)
    # wheels: dark boxes protruding a little below and beside the body
    for xw in (0.32 * L, -0.32 * L):
        for yw in (W / 2 - 0.12, -W / 2 + 0.12):
            b.box(at(xw, yw, 0.34), ax, (0.66, 0.26, 0.68), TYRE, obj_id=obj.obj_id, bottom=False)
    # rear: tail lights and plate on the -x face (e1 x e2 must point backwards: e1 = -left, e2 = up)
    zl = z_body1 - 0.16
    for yl in (W / 2 - 0.08, -W / 2 + 0.38):
        b.add(at(-L / 2 - EPS, yl, zl), -0.3 * ax[1], 0.12 * ax[2], TAIL, obj_id=obj.obj_id, shade=False)
    b.add(at(-L / 2 - EPS, 0.26, z_body0 + 0.08), -0.52 * ax[1], 0.12 * ax[2], PLATE, obj_id=obj.obj_id)
    # front: headlights on the +x face ((e1 x e2) = +x with e1 = +y, e2 = +z)
    for yl in (W / 2 - 0.38, -W / 2 + 0.08):
        b.add(at(L / 2 + EPS, yl, zl), 0.3 * ax[1], 0.12 * ax[2], HEAD, obj_id=obj.obj_id, shade=False)
