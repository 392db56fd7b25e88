"""Landmark signs: a post and a square panel whose face carries an ArUco marker."""

from __future__ import annotations

import numpy as np

from percept.sensors.vehicle import SIGN_PANEL_BOTTOM_M, SIGN_PANEL_SIZE_M

from .patches import PatchBuilder
from .scene import ObjectState

POST = (120, 120, 125)
PANEL_BACK = (150, 150, 155)


def sign_patches(b: PatchBuilder, obj: ObjectState, marker_texture: int) -> None:
    """Add one sign. The pose's yaw is the direction the marker face looks at (towards oncoming traffic)."""
    p = obj.pose
    n = np.array([np.cos(p.yaw_rad), np.sin(p.yaw_rad), 0.0])  # face normal
    r = np.array([-n[1], n[0], 0.0])  # the viewer's right when looking at the face
    up = np.array([0.0, 0.0, 1.0])
    c = np.array([p.x_m, p.y_m, 0.0])
    ax = np.array([n, r, up])
    b.box(c + up * SIGN_PANEL_BOTTOM_M / 2, ax, (0.08, 0.08, SIGN_PANEL_BOTTOM_M), POST, obj_id=obj.obj_id)
    s = SIGN_PANEL_SIZE_M
    # marker face: e1 to the viewer's right, e2 down, so the texture is not mirrored; (e1 x e2) = -n, hence
    # two-sided, with the panel behind it hiding it from the back
    o = c + n * 0.05 - r * s / 2 + up * (SIGN_PANEL_BOTTOM_M + s)
    b.add(o, r * s, -up * s, (255, 255, 255), texture=marker_texture, obj_id=obj.obj_id, shade=False, two_sided=True)
    b.box(c + up * (SIGN_PANEL_BOTTOM_M + s / 2), ax, (0.04, s, s), PANEL_BACK, obj_id=obj.obj_id)
