"""Articulated walking pedestrians: limbs as view-facing capsules on a skeleton with a walking gait.

Proportions follow the usual anthropometric canon (heights as fractions of stature: knee 0.285,
hip 0.53, shoulder 0.82, head 0.13; Winter, *Biomechanics and Motor Control of Human Movement*,
table 4.1). The gait is a sinusoidal hip swing with knee flexion in the swing phase and counter-
swinging arms. Limb quads are turned towards the viewer (the rig centre) so that both cameras see
the same 3D geometry.
"""

from __future__ import annotations

import math

import numpy as np

from .raster import PatchBuilder
from .scene import ObjectState

SHIRTS = [(40, 40, 170), (150, 60, 30), (40, 120, 40), (30, 30, 30), (200, 200, 200), (40, 150, 210),
          (120, 40, 120), (20, 80, 160), (90, 90, 90), (170, 130, 60)]
PANTS = [(60, 40, 30), (30, 30, 30), (110, 80, 50), (80, 80, 80), (120, 60, 30), (40, 40, 60)]
SKINS = [(150, 180, 225), (110, 145, 195), (70, 100, 150), (60, 80, 110)]
HAIR = [(20, 20, 25), (30, 50, 80), (60, 90, 140), (140, 140, 140)]
SHOES = (25, 25, 25)


def _limb(b: PatchBuilder, p0: np.ndarray, p1: np.ndarray, radius: float, view: np.ndarray, color, oid: int) -> None:
    """A capsule-like quad of width 2·radius from p0 to p1, facing the viewer position ``view``."""
    axis = p1 - p0
    mid = (p0 + p1) / 2
    side = np.cross(axis, view - mid)
    n = np.linalg.norm(side)
    if n < 1e-9:
        return
    side *= radius / n
    # e1 along the width, e2 along the limb; e1 x e2 must face the viewer for the back-face test
    o, e1, e2 = p0 - side, 2 * side, axis
    if np.dot(np.cross(e1, e2), view - mid) < 0:
        o, e1 = p0 + side, -2 * side
    b.add(o, e1, e2, color, obj_id=oid, two_sided=True)
    # rounded ends: a disc at each joint
    for p in (p0, p1):
        _disc(b, p, radius, view, color, oid)


def _disc(b: PatchBuilder, c: np.ndarray, radius: float, view: np.ndarray, color, oid: int,
          rx: float | None = None) -> None:
    """A view-facing ellipse centred at c: half-height radius, half-width rx (default radius)."""
    rx = radius if rx is None else rx
    d = view - c
    d /= np.linalg.norm(d) + 1e-12
    up = np.array([0.0, 0.0, 1.0])
    right = np.cross(up, d)
    right /= np.linalg.norm(right) + 1e-12
    upv = np.cross(d, right)
    b.add(c - rx * right - radius * upv, 2 * rx * right, 2 * radius * upv, color, outline=1, obj_id=oid, two_sided=True)


def pedestrian_patches(b: PatchBuilder, obj: ObjectState, view_world: np.ndarray) -> None:
    """Add one pedestrian. The pose's yaw is the walking direction; ``obj.height_m`` its stature."""
    h = obj.height_m
    rng = np.random.default_rng(obj.style)
    shirt = SHIRTS[int(rng.integers(len(SHIRTS)))]
    pants = PANTS[int(rng.integers(len(PANTS)))]
    skin = SKINS[int(rng.integers(len(SKINS)))]
    hair = HAIR[int(rng.integers(len(HAIR)))]
    build = float(rng.uniform(0.9, 1.15))
    p = obj.pose
    fwd = np.array([math.cos(p.yaw_rad), math.sin(p.yaw_rad), 0.0])
    left = np.array([-fwd[1], fwd[0], 0.0])
    up = np.array([0.0, 0.0, 1.0])
    base = np.array([p.x_m, p.y_m, 0.0])
    oid = obj.obj_id
    walking = obj.speed_mps > 0.05
    ph = obj.gait_phase
    swing = 0.42 if walking else 0.0  # hip swing amplitude [rad]

    def pt(x, y, z):
        return base + x * fwd + y * left + z * up

    hip_z, knee_l, shin_l = 0.53 * h, 0.245 * h, 0.245 * h
    sh_z = 0.82 * h
    hip_w, sh_w = 0.09 * h * build, 0.115 * h * build
    # view direction decides how wide the torso looks: frontal shoulders vs side depth
    vdir = view_world - base
    vdir[2] = 0
    vdir /= np.linalg.norm(vdir) + 1e-12
    frontal = abs(float(vdir @ fwd))  # 1 = seen from front/back, 0 = from the side
    torso_half = (0.115 * frontal + 0.07 * (1 - frontal)) * h * build

    # legs: far leg first so the near one is drawn over it (the z-test sorts it anyway)
    for sgn, phase in ((+1, ph), (-1, ph + math.pi)):
        a = swing * math.sin(phase)
        # knee flexes during the forward swing
        flex = (0.5 * swing * max(0.0, math.sin(phase + 0.9)) + 0.05) if walking else 0.03
        hip = pt(0.0, sgn * hip_w * 0.6, hip_z)
        knee = hip + knee_l * (math.sin(a) * fwd - math.cos(a) * up)
        b2 = a - 1.4 * flex
        ankle = knee + shin_l * (math.sin(b2) * fwd - math.cos(b2) * up)
        _limb(b, hip, knee, 0.06 * h * build, view_world, pants, oid)
        _limb(b, knee, ankle, 0.045 * h * build, view_world, pants, oid)
        toe = ankle + 0.13 * h * fwd
        toe[2] = max(toe[2], 0.02)
        _limb(b, ankle, toe, 0.03 * h, view_world, SHOES, oid)
    # torso and head
    pelvis = pt(0, 0, hip_z - 0.02 * h)
    neck = pt(0.01 * h, 0, sh_z + 0.01 * h)
    _limb(b, pelvis, neck, torso_half, view_world, shirt, oid)
    _limb(b, pt(0, 0, sh_z), pt(0, 0, 0.87 * h), 0.03 * h, view_world, skin, oid)
    head_c = pt(0.01 * h, 0, 0.93 * h)
    _disc(b, head_c, 0.066 * h, view_world, skin, oid, rx=0.055 * h)
    _disc(b, head_c + 0.025 * h * up - 0.012 * h * fwd, 0.045 * h, view_world, hair, oid, rx=0.058 * h)
    # arms swing against the legs
    for sgn, phase in ((+1, ph + math.pi), (-1, ph)):
        a = 0.6 * swing * math.sin(phase)
        sh = pt(0, sgn * sh_w, sh_z - 0.02 * h)
        elbow = sh + 0.17 * h * (math.sin(a) * fwd - math.cos(a) * up)
        a2 = a + (0.35 if walking else 0.1)
        wrist = elbow + 0.15 * h * (math.sin(a2) * fwd - math.cos(a2) * up)
        _limb(b, sh, elbow, 0.035 * h * build, view_world, shirt, oid)
        _limb(b, elbow, wrist, 0.028 * h, view_world, skin, oid)
