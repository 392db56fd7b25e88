"""Articulated walking pedestrians: tapered view-facing limbs on a skeleton with a walking gait.

Proportions follow the anthropometric canon (segment lengths and joint heights as fractions of
stature: hip 0.53, knee 0.285, ankle 0.039, shoulder 0.818, chin 0.87, upper arm 0.186, forearm
0.146, foot 0.152, shoulder width 0.259; Winter, *Biomechanics and Motor Control of Human Movement*,
fig. 4.1). Trunk widths and depths are those of a clothed adult (chest 0.18-0.23 h deep, from a shirt
to a padded jacket): a thinner side-view trunk makes crossing pedestrians much harder to recognise for a HOG
people detector (Dalal & Triggs 2005), as it would be for real people. The gait follows normative
sagittal joint angles over the cycle (hip, knee, shoe pitch: heel-off late in stance, toe up at heel
strike) with counter-swinging arms; the whole figure is then lowered or raised so that its lowest
shoe point rests on the ground (z = 0), which gives the pelvis its natural bob.

Limbs and trunk are flat tapered quads turned towards the viewer (the rig centre), so both cameras
see the same 3D geometry. Each is split lengthwise into a lit and a shadowed half (a cheap cylinder
shading under the renderer's sun); shoes are small boxes. Parts that touch at the same depth get a
few millimetres of bias towards the viewer so that the z-test orders them deterministically (arms
over trunk, shirt over trousers, face over hair), never by rounding noise.
"""

from __future__ import annotations

import functools
import math
from typing import NamedTuple

import numpy as np
from numba import njit

from percept.compiled import kernel

from .figure import ROW, box, disc, limb, packed, pymax, scaled
from .scene import ObjectState
from .vec3 import UP, Vec3, add, dot, madd, mul, norm, vec

# BGR colours. Clothing keeps some luminance or hue contrast against the grey asphalt (~100, 97, 95).
SHIRTS = [(40, 40, 175), (95, 45, 20), (35, 90, 30), (28, 28, 30), (225, 225, 222), (205, 140, 80),
          (115, 40, 110), (35, 115, 215), (30, 160, 210), (45, 30, 125), (125, 115, 25), (150, 100, 210),
          (55, 55, 60), (90, 130, 160), (30, 70, 150), (140, 70, 40)]
PANTS = [(120, 75, 40), (85, 55, 35), (30, 30, 32), (70, 105, 135), (50, 50, 55), (40, 60, 95),
         (75, 45, 30), (115, 75, 45)]
SKINS = [(150, 180, 225), (125, 160, 210), (95, 130, 185), (70, 100, 150), (50, 70, 105)]
HAIR = [(20, 20, 25), (25, 40, 65), (45, 75, 120), (80, 150, 190), (150, 150, 155), (30, 30, 90)]
SHOES = [(25, 25, 28), (30, 50, 80), (215, 215, 215), (40, 40, 40)]

# Normal walking over one gait cycle (fraction 0 = heel strike of that leg), degrees; after Winter's
# normative sagittal kinematics. HIP: thigh forwards of the vertical; KNEE: flexion; FOOT: shoe pitch
# relative to the ground, toe down positive (heel-off late in stance, toe up at heel strike). The swing is on the
# low side of normal (knee peak 51 deg, not the mean ~60, as at slower speeds: Koopman et al., J. Biomech. 47, 2014;
# hip back near neutral at toe-off): with the mean curve the trailing shank kicks far back after toe-off, a pose
# that people detectors trained on photos (INRIA) miss.
GAIT_C = np.linspace(0.0, 1.0, 11)
HIP = np.array([22.0, 19.0, 12.0, 5.0, -2.0, -9.0, -1.0, 12.0, 22.0, 25.0, 22.0])
KNEE = np.array([2.0, 10.0, 15.0, 10.0, 8.0, 22.0, 36.0, 51.0, 38.0, 13.0, 2.0])
FOOT = np.array([-10.0, 0.0, 0.0, 0.0, 5.0, 14.0, 34.0, 25.0, 5.0, -8.0, -10.0])


@njit(cache=True)
def _turn(a: float, u: Vec3, b: float, v: Vec3) -> Vec3:
    """a u + b v."""
    return (a * u[0] + b * v[0], a * u[1] + b * v[1], a * u[2] + b * v[2])


@functools.lru_cache(maxsize=256)
def _style(style: int) -> tuple:
    """A figure's look drawn from its style seed, in a fixed order: shirt, trousers, skin, hair and shoe
    colours (BGR, as floats), build, long sleeves, shorts, long hair, bulk (see ``Body``)."""
    rng = np.random.default_rng(style & 0xFFFFFFFF)
    colours = tuple(vec(palette[int(rng.integers(len(palette)))]) for palette in (SHIRTS, PANTS, SKINS, HAIR, SHOES))
    build = float(rng.uniform(0.92, 1.12))
    flags = tuple(bool(rng.random() < q) for q in (0.5, 0.12, 0.3))
    return (*colours, build, *flags, float(rng.uniform(1.0, 1.3)))


class Body(NamedTuple):
    """One pedestrian's frame, look and gait as seen from ``viewer`` (the rig centre) [m, world]: stature ``h``
    [m]; ``fwd``, ``left`` unit vectors of the walking direction at ``base`` (the pose on the ground); ``vdir`` the
    horizontal direction to the viewer; ``cf`` = 1 seen from the front or back, 0 from the side (``cs`` the other
    way); ``lean`` of the trunk [rad]; ``gait`` per leg (left, right) its side (+1, -1) and hip, knee and shoe
    angles [rad]; ``trunk_w`` the half-widths [m] of the trunk parts' ends as seen (pelvis, belly, chest,
    shoulders). Colours are BGR; ``build`` is a width factor, ``hips`` the hips' share of the clothing's bulk."""

    viewer: Vec3
    oid: int
    h: float
    base: Vec3
    fwd: Vec3
    left: Vec3
    vdir: Vec3
    cf: float
    cs: float
    lean: float
    walking: bool
    gait: tuple[tuple[float, float, float, float], tuple[float, float, float, float]]
    trunk_w: tuple[float, float, float, float, float, float, float, float]
    shirt: Vec3
    pants: Vec3
    skin: Vec3
    hair: Vec3
    shoes: Vec3
    build: float
    hips: float
    long_sleeves: bool
    shorts: bool
    long_hair: bool


def _body(obj: ObjectState, view: Vec3) -> Body:
    """``obj``'s Body. ``obj.style`` seeds the colours, build, sleeves, shorts, long hair and bulk (upper-body
    clothing, from a shirt to a padded jacket; the hips get half of it), drawn in a fixed order so that a seed
    always dresses the same figure; the gait cycle fraction of the left leg is ``obj.gait_phase`` / 2π (0 = heel
    strike), the right leg half a cycle on."""
    shirt, pants, skin, hair, shoes, build, long_sleeves, shorts, long_hair, bulk = _style(int(obj.style))
    hips = 1.0 + 0.5 * (bulk - 1.0)
    p = obj.pose
    h = float(obj.height_m)
    fwd = (math.cos(p.yaw_rad), math.sin(p.yaw_rad), 0.0)
    base = (float(p.x_m), float(p.y_m), 0.0)
    walking = obj.speed_mps > 0.05
    c = (obj.gait_phase / (2 * math.pi)) % 1.0
    vdir = (view[0] - base[0], view[1] - base[1], 0.0)
    n = norm(vdir) + 1e-12
    vdir = (vdir[0] / n, vdir[1] / n, vdir[2] / n)
    cf = abs(dot(vdir, fwd))
    cs = math.sqrt(max(0.0, 1.0 - cf * cf))
    if walking:
        # hip, knee and shoe angles of both legs, half a cycle apart
        hip, knee, foot = (np.radians(np.interp((c, (c + 0.5) % 1.0), GAIT_C, t)).tolist() for t in (HIP, KNEE, FOOT))
        gait = tuple((sgn, hip[k], knee[k], foot[k]) for k, sgn in enumerate((1.0, -1.0)))
    else:
        gait = tuple((sgn, 0.02 * sgn, 0.03, 0.0) for sgn in (1.0, -1.0))

    def across(w, d, bk):
        # how wide a trunk part looks [m]: an elliptic cross-section of width w (across) and depth d (front to back),
        # fractions of h, the clothing adding bk to the depth. math.hypot here, CPython's: see figure.py
        return math.hypot(w * cf, d * cs * bk) * h * build

    trunk_w = (across(0.098, 0.086, hips), across(0.086, 0.079, hips), across(0.09, 0.082, hips),
               across(0.086, 0.082, hips), across(0.087, 0.084, bulk), across(0.104, 0.09, bulk),
               across(0.125, 0.086, bulk), across(0.055, 0.058, bulk))
    # the trunk leans forwards a little when walking [rad]
    return Body(view, int(obj.obj_id), h, base, fwd, (-fwd[1], fwd[0], 0.0), vdir, cf, cs, 0.06 if walking else 0.0,
                walking, gait, trunk_w, shirt, pants, skin, hair, shoes, build, hips, long_sleeves, shorts,
                long_hair)


@njit(cache=True)
def _pt(body: Body, x: float, y: float, z: float) -> Vec3:
    """The world point x forwards, y left, z up [m] of the figure's base."""
    return madd(madd(madd(body.base, x, body.fwd), y, body.left), z, UP)


@njit(cache=True)
def _seg(body: Body, ang: float) -> Vec3:
    """Unit vector at angle ``ang`` from straight down, rotated forwards (sagittal plane)."""
    return _turn(math.sin(ang), body.fwd, -math.cos(ang), UP)


@njit(cache=True)
def _trunk_pt(body: Body, z: float, x: float = 0.0) -> Vec3:
    """A point on the trunk's mid-line at height z [fraction of h], leaning forwards about the hips."""
    h = body.h
    return _pt(body, x * h + (z - 0.53) * h * math.sin(body.lean), 0.0, z * h)


@njit(cache=True)
def _legs(rows, n: int, body: Body) -> int:
    """Thigh, shank (trousers, or shorts and skin) and a shoe pitched by the gait, per leg."""
    h, fwd, left, build, view = body.h, body.fwd, body.left, body.build, body.viewer
    hip_z, thigh, shank = 0.53 * h, 0.245 * h, 0.246 * h
    foot_l, ankle_h = 0.155 * h, 0.039 * h
    stance_y = 0.05 * h if body.walking else 0.055 * h
    for sgn, a, knee_flex, toe_down in body.gait:
        b_ang = a - knee_flex
        hip = _pt(body, 0.0, sgn * stance_y, hip_z)
        knee = madd(hip, thigh, _seg(body, a))
        ankle = madd(knee, shank, _seg(body, b_ang))
        if body.shorts:
            mid = madd(hip, 0.55 * thigh, _seg(body, a))
            n = limb(rows, n, view, hip, mid, 0.05 * h * build, 0.043 * h * build, body.pants, 0.005, True, True)
            n = limb(rows, n, view, mid, knee, 0.036 * h * build, 0.03 * h * build, body.skin, 0.004, False, True)
            n = limb(rows, n, view, knee, ankle, 0.033 * h * build, 0.02 * h * build, body.skin, 0.005, True, True)
        else:
            n = limb(rows, n, view, hip, knee, 0.05 * h * build, 0.034 * h * build, body.pants, 0.005, True, True)
            n = limb(rows, n, view, knee, ankle, 0.035 * h * build, 0.026 * h * build, body.pants, 0.005, True, True)
        # the shoe, pitched toe-down at heel-off and toe-up at heel strike
        f_dir = _turn(math.cos(toe_down), fwd, -math.sin(toe_down), UP)
        f_up = _turn(math.sin(toe_down), fwd, math.cos(toe_down), UP)
        shoe_h = 0.06 * h
        centre = madd(madd(ankle, 0.28 * foot_l, f_dir), shoe_h / 2 - ankle_h, f_up)
        n = box(rows, n, centre, (f_dir, left, f_up), (foot_l, 0.058 * h * build, shoe_h), body.shoes)
    return n


@njit(cache=True)
def _trunk(rows, n: int, body: Body) -> int:
    """Pelvis (trousers), torso (shirt) with a lighter chest, shoulders sloping to the neck."""
    w, shirt, view = body.trunk_w, body.shirt, body.viewer
    n = limb(rows, n, view, _trunk_pt(body, 0.465, -0.004), _trunk_pt(body, 0.6), w[0], w[1], body.pants, 0.0,
             False, False)
    n = limb(rows, n, view, _trunk_pt(body, 0.54), _trunk_pt(body, 0.67, 0.006), w[2], w[3], scaled(shirt, 0.95),
             0.01, False, False)
    n = limb(rows, n, view, _trunk_pt(body, 0.665, 0.006), _trunk_pt(body, 0.785, 0.004), w[4], w[5], shirt, 0.01,
             False, False)
    return limb(rows, n, view, _trunk_pt(body, 0.78, 0.004), _trunk_pt(body, 0.845), w[6], w[7], shirt, 0.011,
                False, False)


@njit(cache=True)
def _head(rows, n: int, body: Body) -> int:
    """Neck and head: face, hair cap, hair at the back, eyes when seen from the front, long hair."""
    h, fwd, left, cf, cs, view = body.h, body.fwd, body.left, body.cf, body.cs, body.viewer
    skin, hair = body.skin, body.hair
    n = limb(rows, n, view, _trunk_pt(body, 0.82, 0.005), _trunk_pt(body, 0.885, 0.01), 0.028 * h, 0.028 * h,
             scaled(skin, 0.9), 0.0, False, False)
    head_c = _trunk_pt(body, 0.935, 0.012)
    head_w = (0.048 * cf + 0.055 * cs) * h
    front = dot(body.vdir, fwd)
    face_bias, hair_bias = (0.02, 0.015) if front > -0.3 else (0.012, 0.02)
    n = disc(rows, n, view, head_c, 0.065 * h, head_w, skin, face_bias)
    n = disc(rows, n, view, madd(madd(head_c, 0.022 * h, UP), -0.012 * h, fwd), 0.046 * h, head_w * 1.08, hair,
             hair_bias)
    n = disc(rows, n, view, madd(madd(head_c, 0.006 * h, UP), -0.02 * h, fwd), 0.058 * h, head_w * 1.02, hair,
             hair_bias - 0.004)
    if front > -0.2:  # eyes on the front of the head; hidden by the face or hair from behind
        for s in (+1, -1):
            eye = madd(madd(madd(head_c, 0.046 * h, fwd), 0.018 * h * s, left), 0.004 * h, UP)
            n = disc(rows, n, view, eye, 0.0055 * h, 0.008 * h, (40.0, 35.0, 35.0), 0.01)
    if body.long_hair:
        n = limb(rows, n, view, madd(head_c, -0.025 * h, fwd), madd(madd(head_c, -0.03 * h, fwd), -0.13 * h, UP),
                 0.05 * h, 0.045 * h, hair, 0.012 * cs, True, False)
    return n


@njit(cache=True)
def _arms(rows, n: int, body: Body) -> int:
    """Arms swinging against the legs: upper arm (sleeve), forearm (sleeve or skin), hand."""
    h, left, view = body.h, body.left, body.viewer
    build, hips, skin = body.build, body.hips, body.skin
    sleeve = scaled(body.shirt, 0.93)
    fore = sleeve if body.long_sleeves else skin
    for sgn, hip_a, _, _ in body.gait:
        if body.walking:
            a = -0.8 * (hip_a - math.radians(9.0))
            a2 = a + 0.3 + 0.8 * pymax(0.0, a)
        else:
            a, a2 = 0.0, 0.12
        sh = madd(_trunk_pt(body, 0.795), sgn * 0.113 * h * build, left)
        out = mul(0.07 * sgn, left)  # slight abduction so that the arm hangs clear of the waist
        elbow = madd(sh, 0.186 * h, add(_seg(body, a), out))
        wrist = madd(elbow, 0.146 * h, madd(_seg(body, a2), 0.5, out))
        n = limb(rows, n, view, sh, elbow, 0.035 * h * build * hips, 0.028 * h * build * hips, sleeve, 0.025, True,
                 True)
        n = limb(rows, n, view, elbow, wrist, 0.028 * h * build * hips, 0.021 * h * build, fore, 0.025, False, True)
        n = disc(rows, n, view, madd(wrist, 0.045 * h, _seg(body, a2)), 0.042 * h, 0.024 * h, skin, 0.03)
    return n


@kernel()
def _figure(body: Body) -> np.ndarray:
    """The body's patches, lowered onto the ground and packed: (P, 19)."""
    rows = np.empty((160, ROW))
    # the parts in a fixed order (legs, trunk, head, arms): the order is part of the output
    n = _legs(rows, 0, body)
    n = _trunk(rows, n, body)
    n = _head(rows, n, body)
    n = _arms(rows, n, body)
    return packed(rows, n, body.oid)


def pedestrian_packed(obj: ObjectState, view_world) -> np.ndarray:
    """One pedestrian seen from ``view_world`` (3,) [m, world frame]: its patches packed as ``PatchBatch.pack``
    packs them, (P, 19). The pose's yaw is the walking (facing) direction; ``obj.height_m`` its stature;
    ``obj.style`` seeds clothing, skin, hair and build; ``obj.gait_phase`` [rad] the walking cycle (0 = left heel
    strike), used when ``obj.speed_mps`` > 0.05. The lowest shoe point touches the ground (z = 0) at the pose
    position; every patch carries ``obj.obj_id``."""
    return _figure(_body(obj, vec(view_world)))
